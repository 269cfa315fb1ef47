//! A measurement CSV read in two passes over a stream, holding one line of text at a time
//! (docs/design.md §2.1): the first pass digests the bytes, checks that they are UTF-8, reads
//! every `# key: value` line wherever it stands (all are checked before the header row and the
//! rows) and counts the rows; the second parses the header row and the rows top to bottom. A
//! file whose bytes differ between the passes is refused, never read as a mix of two versions.

use std::fs::File;
use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use sha2::{Digest, Sha256};

use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::metadata::{split_metadata_line, Metadata, LAYOUT_KEY};
use super::table_file::{hex, open_file, unreadable};
use crate::table_text::{is_comment, LineReader};

/// Bytes read from the file at a time: the one buffer of text the reader holds besides a line.
const READ_BUFFER_BYTES: usize = 1 << 16;

/// A reader that digests every byte consumed from it: the SHA-256 of a file read as a stream.
pub(crate) struct Digesting<R> {
    inner: R,
    digest: Sha256,
    length: u64,
}

/// The bytes read by a [`Digesting`] reader: their SHA-256 and count.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fingerprint {
    pub sha256: [u8; 32],
    pub length: u64,
}

impl<R: BufRead> Digesting<R> {
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            digest: Sha256::new(),
            length: 0,
        }
    }

    /// Reads the rest of the bytes and returns the fingerprint of all of them.
    pub(crate) fn finish(mut self) -> std::io::Result<Fingerprint> {
        loop {
            let read = self.fill_buf()?.len();
            if read == 0 {
                break;
            }
            self.consume(read);
        }
        Ok(Fingerprint {
            sha256: self.digest.finalize().into(),
            length: self.length,
        })
    }
}

impl<R: BufRead> Read for Digesting<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let read = available.len().min(out.len());
        out[..read].copy_from_slice(&available[..read]);
        self.consume(read);
        Ok(read)
    }
}

impl<R: BufRead> BufRead for Digesting<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        self.inner.fill_buf()
    }

    fn consume(&mut self, amount: usize) {
        // The bytes being consumed are still the inner reader's buffer: asking for it again
        // reads nothing.
        if let Ok(buffer) = self.inner.fill_buf() {
            self.digest.update(&buffer[..amount.min(buffer.len())]);
        }
        self.length += amount as u64;
        self.inner.consume(amount);
    }
}

/// The lines of a measurement table as read from `reader`, digested.
pub(crate) type StreamedLines<R> = LineReader<Digesting<R>>;

pub(crate) fn stream_lines<R: BufRead>(reader: R) -> StreamedLines<R> {
    LineReader::new(Digesting::new(reader))
}

/// The text of the current line of `lines`, or a refusal of its bytes.
pub(crate) fn line_text<R: BufRead>(lines: &StreamedLines<R>) -> Result<&str, Refusal> {
    lines
        .text()
        .map_err(|r| r.map(|invalid| MeasureErrorKind::InvalidUtf8 { byte: invalid.byte }))
}

/// Moves `lines` to its next line; `false` at the end.
pub(crate) fn next_line<R: BufRead>(lines: &mut StreamedLines<R>) -> Result<bool, Refusal> {
    lines.advance().map_err(unreadable)
}

/// What the first pass learns of a table.
pub(crate) struct TableScan {
    pub fingerprint: Fingerprint,
    /// Whether any line is not blank.
    has_text: bool,
    /// All metadata, or the refusal of its first wrong line (in file order).
    metadata: Result<Metadata, Refusal>,
    /// The line of the header row (the first line that is neither blank nor `#`).
    header_line: Option<u64>,
    /// The data rows after the header row.
    pub rows: usize,
    /// The line, value and value column of the first `# layout:` line.
    pub layout: Option<(u64, String, u64)>,
}

impl TableScan {
    /// Hex SHA-256 of the file's bytes.
    pub(crate) fn sha256(&self) -> String {
        hex(&self.fingerprint.sha256)
    }

    /// The metadata of a table that has a header row, or the first refusal in the order of
    /// checks: an empty file, then the metadata, then a missing header row.
    pub(crate) fn metadata(&mut self) -> Result<Metadata, Refusal> {
        if !self.has_text {
            return Err(Refusal::new(1, 1, MeasureErrorKind::EmptyFile));
        }
        let metadata = std::mem::replace(&mut self.metadata, Ok(Metadata::default()))?;
        match self.header_line {
            Some(_) => Ok(metadata),
            None => Err(Refusal::new(1, 1, MeasureErrorKind::NoHeader)),
        }
    }
}

/// The first pass over a table: refused only if it cannot be read or is not UTF-8 (which is
/// checked before anything else); what else is wrong is for [`TableScan::metadata`] to say.
pub(crate) fn scan_table<R: BufRead>(reader: R) -> Result<TableScan, Refusal> {
    let mut lines = stream_lines(reader);
    let mut metadata = Ok(Metadata::default());
    let (mut has_text, mut header_line, mut rows, mut layout) = (false, None, 0, None);
    while next_line(&mut lines)? {
        let number = lines.number();
        let line = line_text(&lines)?;
        if line.trim().is_empty() {
            continue;
        }
        has_text = true;
        if !is_comment(line) {
            match header_line {
                None => header_line = Some(number),
                Some(_) => rows += 1,
            }
            continue;
        }
        let Some((key, value, column)) = split_metadata_line(line) else {
            continue;
        };
        if key == LAYOUT_KEY && layout.is_none() {
            layout = Some((number, value.to_owned(), column));
        }
        if let Ok(known) = &mut metadata {
            if let Err(refusal) = known.add(number, key, value, column) {
                metadata = Err(refusal);
            }
        }
    }
    let fingerprint = lines.into_inner().finish().map_err(unreadable)?;
    Ok(TableScan {
        fingerprint,
        has_text,
        metadata,
        header_line,
        rows,
        layout,
    })
}

/// The file at `path` opened for a pass, or refused as a whole.
pub(crate) fn open_table(path: &Path) -> Result<BufReader<File>, MeasureError> {
    Ok(BufReader::with_capacity(
        READ_BUFFER_BYTES,
        open_file(path)?,
    ))
}

/// The first pass over the file at `path`.
pub(crate) fn scan_file(path: &Path) -> Result<TableScan, MeasureError> {
    scan_table(open_table(path)?).map_err(|r| r.in_file(path))
}

/// Hex SHA-256 of the bytes of the file at `path`, read as a stream (the check of a fit's
/// source against its record, which needs no more of the file).
pub(crate) fn file_sha256(path: &Path) -> Result<String, MeasureError> {
    let fingerprint = Digesting::new(open_table(path)?).finish();
    Ok(hex(&fingerprint
        .map_err(|e| unreadable(e).in_file(path))?
        .sha256))
}

/// The outcome of a second pass over `lines` that began where the first did: `parsed` unless
/// the bytes (read to their end) differ from those `first` fingerprinted.
pub(crate) fn same_file<R: BufRead, T>(
    lines: StreamedLines<R>,
    first: &Fingerprint,
    parsed: Result<T, Refusal>,
) -> Result<T, Refusal> {
    match lines.into_inner().finish() {
        Ok(second) if second != *first => {
            Err(Refusal::new(0, 0, MeasureErrorKind::ChangedWhileRead))
        }
        Ok(_) => parsed,
        // A refusal found before the read failed stands; a complete parse cannot be trusted.
        Err(error) => parsed.and(Err(unreadable(error))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "# material: paint\r\n\ntheta_i_deg,theta_r_deg,m00\r30,40,0.5\r\n\
                        # layout: a.toml\n# wavelength_um: 10\n31,41,0.4\n# operator: Zo\u{eb}\n";

    /// The digest of a stream is that of its bytes, however the reads split them.
    #[test]
    fn the_digest_is_of_every_byte_read() {
        let whole: [u8; 32] = Sha256::digest(TEXT.as_bytes()).into();
        for capacity in [1, 3, 64] {
            let mut lines = stream_lines(BufReader::with_capacity(capacity, TEXT.as_bytes()));
            // Reading part of the lines, then finishing, digests all the bytes.
            assert!(next_line(&mut lines).unwrap() && next_line(&mut lines).unwrap());
            let fingerprint = lines.into_inner().finish().unwrap();
            assert_eq!(fingerprint.sha256, whole);
            assert_eq!(fingerprint.length, TEXT.len() as u64);
        }
    }

    /// The first pass reads metadata wherever it stands, counts the rows after the header row
    /// and notes where a `# layout:` line stands.
    #[test]
    fn the_first_pass_reads_metadata_everywhere_and_counts_rows() {
        let mut scan = scan_table(TEXT.as_bytes()).unwrap();
        assert_eq!((scan.header_line, scan.rows), (Some(3), 2));
        assert_eq!(scan.layout, Some((5, "a.toml".to_owned(), 11)));
        let metadata = scan.metadata().unwrap();
        assert_eq!(metadata.material.as_deref(), Some("paint"));
        assert_eq!(metadata.wavelength.map(|w| (w.um, w.line)), Some((10.0, 6)));
        // A wrong metadata line is reported after the bytes are known to be UTF-8.
        let wrong = format!("# wavelength_um: x\n{TEXT}\u{b5}");
        assert!(scan_table(wrong.as_bytes()).unwrap().metadata().is_err());
        let not_utf8 = [wrong.as_bytes(), b"\xff"].concat();
        let refusal = scan_table(&not_utf8[..]).err().unwrap();
        assert_eq!((refusal.line, refusal.column), (10, 2));
        assert_eq!(refusal.kind, MeasureErrorKind::InvalidUtf8 { byte: 0xff });
    }
}

//! [`lines`](super::lines) of a table read from a [`BufRead`], one line held at a time: a
//! measurement file of a million rows is parsed without its text in memory (docs/design.md
//! §2.1). The lines, their numbers, the byte-order mark and the refusal of bytes that are not
//! UTF-8 are exactly those of [`lines`](super::lines) after [`decode_utf8`](super::decode_utf8).

use std::io::BufRead;

use super::{last_column, InvalidUtf8, Refusal};

/// The UTF-8 byte-order mark that spreadsheets write before the text.
const BYTE_ORDER_MARK: &[u8] = b"\xef\xbb\xbf";

/// A reader's lines without their terminators, numbered from 1: "\r\n", "\n" or a bare "\r"
/// each end a line, and the text after the last terminator is the last line (an empty one
/// after a final "\n" or "\r\n", none after a final bare "\r"), as [`lines`](super::lines)
/// splits a whole text.
pub struct LineReader<R> {
    reader: R,
    /// The current line's bytes (the buffer is reused from line to line).
    line: Vec<u8>,
    number: u64,
    /// The current line ended with '\r': a '\n' right after it belongs to that terminator.
    after_carriage_return: bool,
    /// The current line began after a bare '\r' that ended a line of this column count plus one.
    after_bare_return: Option<u64>,
    /// The last line has been read.
    finished: bool,
}

impl<R: BufRead> LineReader<R> {
    pub fn new(reader: R) -> Self {
        Self {
            reader,
            line: Vec::new(),
            number: 0,
            after_carriage_return: false,
            after_bare_return: None,
            finished: false,
        }
    }

    /// Moves to the next line; `false` once every line has been read.
    pub fn advance(&mut self) -> std::io::Result<bool> {
        if self.finished {
            return Ok(false);
        }
        self.after_bare_return = None;
        if std::mem::take(&mut self.after_carriage_return) {
            match self.reader.fill_buf()?.first() {
                // A '\r' that ends the text ends the line before it and starts none (as one
                // before '\n' does).
                None => {
                    self.finished = true;
                    return Ok(false);
                }
                Some(b'\n') => self.reader.consume(1),
                Some(_) => {
                    self.after_bare_return =
                        Some(last_column(&String::from_utf8_lossy(&self.line)));
                }
            }
        }
        self.line.clear();
        loop {
            let buffer = self.reader.fill_buf()?;
            if buffer.is_empty() {
                self.finished = true;
                break;
            }
            match buffer.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(end) => {
                    self.line.extend_from_slice(&buffer[..end]);
                    self.after_carriage_return = buffer[end] == b'\r';
                    self.reader.consume(end + 1);
                    break;
                }
                None => {
                    let read = buffer.len();
                    self.line.extend_from_slice(buffer);
                    self.reader.consume(read);
                }
            }
        }
        self.number += 1;
        if self.number == 1 && self.line.starts_with(BYTE_ORDER_MARK) {
            self.line.drain(..BYTE_ORDER_MARK.len());
        }
        Ok(true)
    }

    /// The current line's number (1-based).
    pub fn number(&self) -> u64 {
        self.number
    }

    /// The current line's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.line
    }

    /// The current line's text, or its first byte that is not UTF-8, refused at this line and
    /// at the column just after the valid text (as [`decode_utf8`](super::decode_utf8) refuses
    /// it: a line terminator is ASCII, so no character spans two lines).
    pub fn text(&self) -> Result<&str, Refusal<InvalidUtf8>> {
        std::str::from_utf8(&self.line).map_err(|e| {
            let byte = self.line[e.valid_up_to()];
            // Right after a bare '\r' the whole-text decode places the byte at the end of the
            // line that '\r' ended (a text's final '\r' starts no line).
            if let (0, Some(column)) = (e.valid_up_to(), self.after_bare_return) {
                return Refusal::new(self.number - 1, column, InvalidUtf8 { byte });
            }
            let valid = &self.line[..e.valid_up_to()];
            // The valid prefix is UTF-8 by construction, so the lossy decode is exact.
            let column = last_column(&String::from_utf8_lossy(valid));
            Refusal::new(self.number, column, InvalidUtf8 { byte })
        })
    }

    /// The reader, positioned after the last line read.
    pub fn into_inner(self) -> R {
        self.reader
    }
}

#[cfg(test)]
mod tests {
    use super::super::{decode_utf8, lines};
    use super::*;
    use std::io::BufReader;

    /// Every line of `bytes` read through a buffer of `capacity` bytes, or the first refusal.
    fn streamed(bytes: &[u8], capacity: usize) -> Result<Vec<(u64, String)>, Refusal<InvalidUtf8>> {
        let mut reader = LineReader::new(BufReader::with_capacity(capacity, bytes));
        let mut read = Vec::new();
        while reader.advance().unwrap() {
            read.push((reader.number(), reader.text()?.to_owned()));
        }
        Ok(read)
    }

    fn in_memory(bytes: &[u8]) -> Result<Vec<(u64, String)>, Refusal<InvalidUtf8>> {
        let text = decode_utf8(bytes)?;
        Ok(lines(text).map(|(n, line)| (n, line.to_owned())).collect())
    }

    const TEXTS: [&[u8]; 19] = [
        b"ok\r\xff",
        b"ok\r\n\xff",
        b"",
        b"a\r",
        b"a\r\r",
        b"\r\r\n\r",
        b"\n",
        b"\r",
        b"\r\n",
        b"a\r\r\nb",
        b"\xef\xbb\xbfh,x\r\n1,2\r\n",
        b"\xef\xbb\xbf",
        b"a\n\n\rb\r\r\rc\n",
        b"# \xc2\xb5m: 1\r\xe2\x82\xac\r\n",
        b"x\n\xef\xbb\xbfy",
        b"ab\rc\xc3",
        b"# a: b\nthe\xffta_i_deg",
        b"ok\r\xe2\x82",
        b"\xef\xbb\xff",
    ];

    /// The streaming reader splits, numbers and refuses as the in-memory one, whatever the
    /// buffer size: terminators, multi-byte characters and the byte-order mark spanning two
    /// buffers included.
    #[test]
    fn streamed_lines_are_the_in_memory_lines() {
        for text in TEXTS {
            for capacity in [1, 2, 3, 4, 7, 8192] {
                assert_eq!(
                    streamed(text, capacity),
                    in_memory(text),
                    "{:?} through a buffer of {capacity}",
                    String::from_utf8_lossy(text)
                );
            }
        }
    }

    /// Every text of up to 6 bytes from terminators, a letter, a two-byte character and a byte
    /// that is never UTF-8, with and without a byte-order mark.
    #[test]
    fn every_short_text_streams_as_in_memory() {
        const ALPHABET: [u8; 6] = [b'a', b'\r', b'\n', 0xc3, 0xa9, 0xff];
        for length in 0..=6u32 {
            for code in 0..ALPHABET.len().pow(length) {
                let text: Vec<u8> = (0..length)
                    .map(|place| ALPHABET[code / ALPHABET.len().pow(place) % ALPHABET.len()])
                    .collect();
                let marked = [BYTE_ORDER_MARK, &text].concat();
                for bytes in [&text, &marked] {
                    for capacity in [1, 2, 5] {
                        assert_eq!(streamed(bytes, capacity), in_memory(bytes), "{bytes:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_bare_carriage_return_at_a_buffer_boundary_ends_one_line() {
        // The '\r' is the last byte of the first 4-byte buffer; the next buffer starts with a
        // line, not with its '\n'.
        assert_eq!(
            streamed(b"abc\rdef\r\nghi", 4).unwrap(),
            [(1, "abc".into()), (2, "def".into()), (3, "ghi".into())]
        );
        // "\r\n" split across two buffers is one terminator.
        assert_eq!(
            streamed(b"abc\r\ndef", 4).unwrap(),
            [(1, "abc".into()), (2, "def".into())]
        );
    }

    #[test]
    fn a_character_split_across_buffers_is_read_whole() {
        // 'µ' (c2 b5) and '€' (e2 82 ac) straddle the 2-byte buffers.
        let lines = streamed("aµ€b\nµ".as_bytes(), 2).unwrap();
        assert_eq!(lines, [(1, "aµ€b".into()), (2, "µ".into())]);
    }

    #[test]
    fn the_reader_holds_one_line_at_a_time() {
        let text: String = (0..1000).map(|i| format!("{i},{}\r\n", i * 2)).collect();
        let mut reader = LineReader::new(BufReader::with_capacity(16, text.as_bytes()));
        let mut count = 0;
        while reader.advance().unwrap() {
            count += 1;
            assert!(
                reader.line.capacity() < 64,
                "line {count} kept the text before it"
            );
        }
        assert_eq!(count, 1001);
    }
}

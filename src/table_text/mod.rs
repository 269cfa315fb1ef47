//! The one reader of text tables (docs/design.md §2.1, §2.5, §2.8, §2.9): every CSV-like file
//! irpol reads — a measurement CSV, a table read through an instrument layout, an atmosphere
//! table, a weather CSV, an EPW or TMY3 file — goes through the same pieces:
//! - [`lines`]: the text's lines, numbered from 1 ("\r\n", "\n" and a bare "\r" each end one),
//!   after [`decode_utf8`] has refused bytes that are not UTF-8 at their line and column;
//!   [`LineReader`] reads the same lines from a stream, one at a time;
//! - [`split_fields`]: the one tokenizer, fields that remember their column;
//! - [`ColumnMap`]: a header row's names mapped onto the columns a reader knows;
//! - [`Refusal`] / [`TableError`]: the one "refused at file:line:column: what is wrong and
//!   what to fix".
//!
//! The readers differ only in what their columns mean, and say so in their own words.

mod columns;
mod fields;
mod refusal;
mod stream;

pub use columns::{ColumnMap, HeaderProblem};
pub use fields::{field_delimiter, split_fields, wrong_delimiter, Delimiter, Field, TokenProblem};
pub use refusal::{Problem, Refusal, TableError};
pub use stream::LineReader;

/// The lines of a text without their terminators, numbered from 1: "\r\n", "\n", or a bare
/// "\r" (old Mac spreadsheet exports) each end a line.
pub fn lines(text: &str) -> impl Iterator<Item = (u64, &str)> {
    text.split('\n')
        .flat_map(|line| line.strip_suffix('\r').unwrap_or(line).split('\r'))
        .zip(1..)
        .map(|(line, number)| (number, line))
}

/// Whether a line is a `#` comment.
pub fn is_comment(line: &str) -> bool {
    line.trim_start().starts_with('#')
}

/// The numbered [`lines`] that hold a header or a row: neither blank nor a `#` comment.
pub fn content_lines(text: &str) -> impl Iterator<Item = (u64, &str)> {
    lines(text).filter(|(_, line)| !line.trim().is_empty() && !is_comment(line))
}

/// The column just after the end of `line` (where a missing field would start).
pub fn last_column(line: &str) -> u64 {
    line.chars().count() as u64 + 1
}

/// A byte that is not UTF-8, and where.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InvalidUtf8 {
    pub byte: u8,
}

/// The text of a table without a leading byte-order mark (spreadsheets write one), or the first
/// byte that is not UTF-8, refused at its line and at the column just after the valid text.
pub fn decode_utf8(bytes: &[u8]) -> Result<&str, Refusal<InvalidUtf8>> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        // The valid prefix is UTF-8 by construction, so the lossy decode is exact.
        let before = String::from_utf8_lossy(&bytes[..e.valid_up_to()]);
        let (line_number, last_line) = lines(without_bom(&before)).last().unwrap_or((1, ""));
        let byte = bytes[e.valid_up_to()];
        Refusal::new(line_number, last_column(last_line), InvalidUtf8 { byte })
    })?;
    Ok(without_bom(text))
}

fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// A field as a finite number, or why not: empty, not a decimal literal, or not finite (Rust
/// parses "NaN", "inf" and overflowing literals such as 1e999 as non-finite).
pub fn parse_finite(text: &str) -> Result<f64, NumberProblem> {
    if text.is_empty() {
        return Err(NumberProblem::Empty);
    }
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        Ok(_) => Err(NumberProblem::NotFinite),
        Err(_) => Err(NumberProblem::NotANumber),
    }
}

/// Why a field is not a finite number ([`parse_finite`]); each reader words it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NumberProblem {
    Empty,
    NotANumber,
    NotFinite,
}

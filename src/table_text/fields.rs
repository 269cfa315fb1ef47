//! The tokenizer of every text table: one line split into trimmed fields that remember their
//! character column, so every refusal can point at `line:column` (docs/design.md §2.1).
//!
//! Written by hand rather than with the `csv` crate because the crate reports positions per
//! record, not per field (the weather reader once re-scanned each line to find its columns).
//! Fields are separated by ','; surrounding whitespace is trimmed; a field may be wrapped in
//! double quotes (with `""` for a literal quote), as R's `write.csv` and spreadsheets write
//! column names. A quoted field cannot span lines.

use std::borrow::Cow;
use std::iter::Peekable;
use std::str::CharIndices;

use super::Refusal;

/// Why a line cannot be split into fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum TokenProblem {
    #[error("fields are separated by {0}, expected ','")]
    WrongDelimiter(Delimiter),
    #[error("quoted field has no closing '\"'")]
    UnterminatedQuote,
    #[error("unexpected text after the closing '\"' of a quoted field")]
    TextAfterQuote,
}

/// A field separator found where ',' was expected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    Semicolon,
    Tab,
    Pipe,
}

impl Delimiter {
    /// The separator a character would be, if it is one of the common non-comma ones.
    fn from_char(c: char) -> Option<Self> {
        match c {
            ';' => Some(Self::Semicolon),
            '\t' => Some(Self::Tab),
            '|' => Some(Self::Pipe),
            _ => None,
        }
    }
}

impl std::fmt::Display for Delimiter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Semicolon => "';'",
            Self::Tab => "tabs",
            Self::Pipe => "'|'",
        })
    }
}

/// One field of a line: its trimmed (and unquoted) text and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Field<'a> {
    pub text: Cow<'a, str>,
    /// 1-based character column of the first non-blank character of the field (the opening
    /// quote of a quoted field); for a blank field, the column just after the preceding ','.
    pub column: u64,
    pub quoted: bool,
}

/// Splits line `number` (its text `line`, without its terminator) at ','; a malformed quote is
/// refused at its column.
pub fn split_fields(number: u64, line: &str) -> Result<Vec<Field<'_>>, Refusal<TokenProblem>> {
    split_line(line).map_err(|(column, problem)| Refusal::new(number, column, problem))
}

/// A refusal if an unquoted field of `fields` holds a ';', tab or '|': the file is separated by
/// that character (a European spreadsheet export, a TSV), not by ','.
pub fn wrong_delimiter(line: u64, fields: &[Field<'_>]) -> Option<Refusal<TokenProblem>> {
    fields.iter().find_map(|field| field_delimiter(line, field))
}

/// [`wrong_delimiter`] of one field.
pub fn field_delimiter(line: u64, field: &Field<'_>) -> Option<Refusal<TokenProblem>> {
    if field.quoted {
        return None;
    }
    field
        .text
        .chars()
        .enumerate()
        .find_map(|(offset, c)| Delimiter::from_char(c).map(|found| (offset, found)))
        .map(|(offset, found)| {
            Refusal::new(
                line,
                field.column + offset as u64,
                TokenProblem::WrongDelimiter(found),
            )
        })
}

/// [`split_fields`] without the line number.
fn split_line(line: &str) -> Result<Vec<Field<'_>>, (u64, TokenProblem)> {
    // One allocation per line, of the right size unless a quoted field holds a ','.
    let commas = line.bytes().filter(|&b| b == b',').count();
    let mut fields = Vec::with_capacity(commas + 1);
    let mut cursor = Cursor {
        line,
        chars: line.char_indices().peekable(),
        column: 1,
    };
    loop {
        // Skip leading blanks of the field (a ',' is not blank).
        let blank_start = cursor.column;
        cursor.skip_blanks();
        let field_column = cursor.column;
        let field = match cursor.peek() {
            Some((_, '"')) => cursor.quoted_field(field_column)?,
            Some((start, _)) => cursor.bare_field(start, field_column),
            None => Field {
                text: Cow::Borrowed(""),
                column: blank_start,
                quoted: false,
            },
        };
        fields.push(field);
        // Here the next character is ',' or the line has ended.
        if cursor.advance().is_none() {
            return Ok(fields);
        }
    }
}

/// A position in a line, counting character columns.
struct Cursor<'a> {
    line: &'a str,
    chars: Peekable<CharIndices<'a>>,
    /// 1-based column of the character `chars` yields next.
    column: u64,
}

impl<'a> Cursor<'a> {
    fn peek(&mut self) -> Option<(usize, char)> {
        self.chars.peek().copied()
    }

    /// The next character, moving past it.
    fn advance(&mut self) -> Option<(usize, char)> {
        let next = self.chars.next();
        if next.is_some() {
            self.column += 1;
        }
        next
    }

    /// Moves past blanks, stopping at a ',' or anything else.
    fn skip_blanks(&mut self) {
        while let Some((_, c)) = self.peek() {
            if c == ',' || !c.is_whitespace() {
                break;
            }
            self.advance();
        }
    }

    /// The field whose opening quote is next (at `field_column`): its text up to the closing
    /// quote with `""` read as '"'; only blanks may follow before the next ','.
    fn quoted_field(&mut self, field_column: u64) -> Result<Field<'a>, (u64, TokenProblem)> {
        self.advance();
        let mut text = String::new();
        let mut closed = false;
        while let Some((_, c)) = self.advance() {
            if c != '"' {
                text.push(c);
            } else if matches!(self.peek(), Some((_, '"'))) {
                self.advance();
                text.push('"');
            } else {
                closed = true;
                break;
            }
        }
        if !closed {
            return Err((field_column, TokenProblem::UnterminatedQuote));
        }
        while let Some((_, c)) = self.peek() {
            if c == ',' {
                break;
            }
            if !c.is_whitespace() {
                return Err((self.column, TokenProblem::TextAfterQuote));
            }
            self.advance();
        }
        Ok(Field {
            text: Cow::Owned(text),
            column: field_column,
            quoted: true,
        })
    }

    /// The unquoted field starting at byte `start` (column `field_column`), up to the next ','
    /// or the end of the line, its trailing blanks trimmed.
    fn bare_field(&mut self, start: usize, field_column: u64) -> Field<'a> {
        let line = self.line;
        let mut end = line.len();
        while let Some((i, c)) = self.peek() {
            if c == ',' {
                end = i;
                break;
            }
            self.advance();
        }
        Field {
            text: Cow::Borrowed(line[start..end].trim_end()),
            column: field_column,
            quoted: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts_and_columns(line: &str) -> Vec<(String, u64)> {
        split_line(line)
            .unwrap()
            .into_iter()
            .map(|f| (f.text.into_owned(), f.column))
            .collect()
    }

    #[test]
    fn plain_fields_keep_their_columns() {
        assert_eq!(
            texts_and_columns("60,0,55"),
            vec![("60".into(), 1), ("0".into(), 4), ("55".into(), 6)]
        );
    }

    #[test]
    fn whitespace_is_trimmed_and_column_points_at_content() {
        assert_eq!(
            texts_and_columns("  a , b\t,c  "),
            vec![("a".into(), 3), ("b".into(), 7), ("c".into(), 10)]
        );
    }

    #[test]
    fn empty_fields_point_after_the_comma() {
        assert_eq!(
            texts_and_columns("a,,b,"),
            vec![
                ("a".into(), 1),
                ("".into(), 3),
                ("b".into(), 4),
                ("".into(), 6)
            ]
        );
        assert_eq!(texts_and_columns(""), vec![("".into(), 1)]);
    }

    #[test]
    fn columns_count_characters_not_bytes() {
        // 'θ' is two bytes in UTF-8 but one column.
        assert_eq!(
            texts_and_columns("θ,x"),
            vec![("θ".into(), 1), ("x".into(), 3)]
        );
    }

    #[test]
    fn quoted_fields_are_unquoted() {
        let fields = split_line(r#""theta_i_deg", "a,""b""" ,c"#).unwrap();
        assert_eq!(fields[0].text, "theta_i_deg");
        assert!(fields[0].quoted);
        assert_eq!(fields[1].text, r#"a,"b""#);
        assert_eq!(fields[1].column, 16);
        assert_eq!(fields[2].text, "c");
        assert_eq!(fields[2].column, 27);
        assert!(!fields[2].quoted);
    }

    #[test]
    fn malformed_quotes_are_refused_with_their_column() {
        assert_eq!(
            split_line(r#"a, "b"#).unwrap_err(),
            (4, TokenProblem::UnterminatedQuote)
        );
        assert_eq!(
            split_line(r#""b"x,c"#).unwrap_err(),
            (4, TokenProblem::TextAfterQuote)
        );
    }

    #[test]
    fn another_delimiter_is_named_at_its_column() {
        let fields = split_line("a;b,\"c;d\"").unwrap();
        assert_eq!(
            wrong_delimiter(4, &fields),
            Some(Refusal::new(
                4,
                2,
                TokenProblem::WrongDelimiter(Delimiter::Semicolon)
            ))
        );
        assert_eq!(wrong_delimiter(4, &split_line("a,\"c;d\"").unwrap()), None);
    }
}

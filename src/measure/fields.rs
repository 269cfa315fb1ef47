//! Splitting one CSV line into trimmed fields that remember their character column, so every
//! refusal can point at `line:column` (docs/design.md §2.1).
//!
//! Written by hand rather than with the `csv` crate because the crate reports positions per
//! record, not per field. Fields are separated by ','; surrounding whitespace is trimmed; a field
//! may be wrapped in double quotes (with `""` for a literal quote), as R's `write.csv` and
//! spreadsheets write column names. A quoted field cannot span lines.

use std::borrow::Cow;

use super::error::MeasureErrorKind;

/// One field of a line: its trimmed (and unquoted) text and where it starts.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Field<'a> {
    pub text: Cow<'a, str>,
    /// 1-based character column of the first non-blank character of the field (the opening
    /// quote of a quoted field); for a blank field, the column just after the preceding ','.
    pub column: u64,
    pub quoted: bool,
}

/// Splits `line` (without its line terminator) at ','. On a malformed quote returns the column
/// and the reason.
pub(crate) fn split_fields(line: &str) -> Result<Vec<Field<'_>>, (u64, MeasureErrorKind)> {
    let mut fields = Vec::new();
    let mut chars = line.char_indices().peekable();
    // 1-based column of the character `chars` yields next.
    let mut column: u64 = 1;
    loop {
        // Skip leading blanks of the field (a ',' is not blank).
        let blank_start = column;
        while let Some(&(_, c)) = chars.peek() {
            if c == ',' || !c.is_whitespace() {
                break;
            }
            chars.next();
            column += 1;
        }
        let field_column = column;
        match chars.peek().copied() {
            Some((_, '"')) => {
                chars.next();
                column += 1;
                let mut text = String::new();
                let mut closed = false;
                while let Some((_, c)) = chars.next() {
                    column += 1;
                    if c != '"' {
                        text.push(c);
                    } else if matches!(chars.peek(), Some(&(_, '"'))) {
                        chars.next();
                        column += 1;
                        text.push('"');
                    } else {
                        closed = true;
                        break;
                    }
                }
                if !closed {
                    return Err((field_column, MeasureErrorKind::UnterminatedQuote));
                }
                while let Some(&(_, c)) = chars.peek() {
                    if c == ',' {
                        break;
                    }
                    if !c.is_whitespace() {
                        return Err((column, MeasureErrorKind::TextAfterQuote));
                    }
                    chars.next();
                    column += 1;
                }
                fields.push(Field {
                    text: Cow::Owned(text),
                    column: field_column,
                    quoted: true,
                });
            }
            Some((start, _)) => {
                let mut end = line.len();
                while let Some(&(i, c)) = chars.peek() {
                    if c == ',' {
                        end = i;
                        break;
                    }
                    chars.next();
                    column += 1;
                }
                fields.push(Field {
                    text: Cow::Borrowed(line[start..end].trim_end()),
                    column: field_column,
                    quoted: false,
                });
            }
            None => {
                fields.push(Field {
                    text: Cow::Borrowed(""),
                    column: blank_start,
                    quoted: false,
                });
            }
        }
        // Here the next character is ',' or the line has ended.
        match chars.next() {
            Some(_) => column += 1,
            None => return Ok(fields),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts_and_columns(line: &str) -> Vec<(String, u64)> {
        split_fields(line)
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
        let fields = split_fields(r#""theta_i_deg", "a,""b""" ,c"#).unwrap();
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
            split_fields(r#"a, "b"#).unwrap_err(),
            (4, MeasureErrorKind::UnterminatedQuote)
        );
        assert_eq!(
            split_fields(r#""b"x,c"#).unwrap_err(),
            (4, MeasureErrorKind::TextAfterQuote)
        );
    }
}

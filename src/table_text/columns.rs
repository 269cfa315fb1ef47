//! A header row mapped onto the columns a reader knows: which field holds each, refusing an
//! empty, unknown (unless the reader passes unknown columns over) or repeated name at its
//! column, and a field separated by another delimiter than ','.

use super::fields::{field_delimiter, Field, TokenProblem};
use super::Refusal;

/// Why a header row is refused; each reader words it (and adds its hint).
#[derive(Debug, Clone, PartialEq)]
pub enum HeaderProblem {
    /// An unquoted name holds ';', a tab or '|'.
    Token(TokenProblem),
    /// An empty name (a doubled or trailing ',').
    Empty,
    /// A name the reader does not know, as written.
    Unknown(String),
    /// A name whose column is already given, at the header's character column `first_column`.
    Duplicate { name: String, first_column: u64 },
}

/// The columns of a header row: for each field, the reader's column it holds (if known).
/// Several names may map onto one column (aliases: the reader's `known` says which).
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnMap<C> {
    /// The known column of each field, in file order.
    known: Vec<Option<C>>,
    /// Each field's 1-based character column in the header line.
    columns: Vec<u64>,
    /// Each field's name as written.
    names: Vec<String>,
}

impl<C: Copy + PartialEq> ColumnMap<C> {
    /// Maps the `fields` of header line `line` through `known` (a name's column, if the reader
    /// knows it). With `unknown_allowed` an unknown name is kept as a column the reader does not
    /// read; otherwise it is refused.
    pub fn of_header(
        line: u64,
        fields: &[Field<'_>],
        known: impl Fn(&str) -> Option<C>,
        unknown_allowed: bool,
    ) -> Result<Self, Refusal<HeaderProblem>> {
        let mut map = ColumnMap {
            known: Vec::with_capacity(fields.len()),
            columns: fields.iter().map(|f| f.column).collect(),
            names: fields.iter().map(|f| f.text.to_string()).collect(),
        };
        for field in fields {
            let refuse = |problem| Refusal::new(line, field.column, problem);
            if let Some(refusal) = field_delimiter(line, field) {
                return Err(refusal.map(HeaderProblem::Token));
            }
            let name = field.text.as_ref();
            let column = known(name);
            if column.is_none() && !unknown_allowed {
                return Err(refuse(match name.is_empty() {
                    true => HeaderProblem::Empty,
                    false => HeaderProblem::Unknown(name.to_string()),
                }));
            }
            if let Some(first) = column.and_then(|c| map.field(c)) {
                return Err(refuse(HeaderProblem::Duplicate {
                    name: name.to_string(),
                    first_column: map.columns[first],
                }));
            }
            map.known.push(column);
        }
        Ok(map)
    }

    /// The field index of `column`, if the header has it.
    pub fn field(&self, column: C) -> Option<usize> {
        self.known.iter().position(|&c| c == Some(column))
    }

    pub fn has(&self, column: C) -> bool {
        self.field(column).is_some()
    }

    /// The first of `required` the header lacks.
    pub fn missing(&self, required: &[C]) -> Option<C> {
        required.iter().copied().find(|&c| !self.has(c))
    }

    /// The known column of each field, in file order (`None`: a column not read).
    pub fn known(&self) -> &[Option<C>] {
        &self.known
    }

    /// The names of the header row, as written, in file order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The 1-based character column of the header's field `field`.
    pub fn header_column(&self, field: usize) -> u64 {
        self.columns[field]
    }

    /// The number of fields every row must have.
    pub fn width(&self) -> usize {
        self.known.len()
    }
}

#[cfg(test)]
mod tests {
    use super::super::split_fields;
    use super::*;

    fn map(header: &str, unknown_allowed: bool) -> Result<ColumnMap<u8>, Refusal<HeaderProblem>> {
        let known = |name: &str| match name {
            "a" | "alpha" => Some(0),
            "b" => Some(1),
            _ => None,
        };
        ColumnMap::of_header(2, &split_fields(2, header).unwrap(), known, unknown_allowed)
    }

    #[test]
    fn names_and_aliases_map_onto_columns() {
        let columns = map("b, alpha,x", true).unwrap();
        assert_eq!((columns.field(0), columns.field(1)), (Some(1), Some(0)));
        assert_eq!(columns.known(), [Some(1), Some(0), None]);
        assert_eq!((columns.width(), columns.header_column(1)), (3, 4));
        assert_eq!(columns.missing(&[1, 0]), None);
        assert_eq!(map("b", true).unwrap().missing(&[1, 0]), Some(0));
    }

    #[test]
    fn header_problems_point_at_their_column() {
        let problem = |header: &str| {
            let refusal = map(header, false).unwrap_err();
            (refusal.column, refusal.kind)
        };
        assert_eq!(problem("a,,b"), (3, HeaderProblem::Empty));
        assert_eq!(problem("a,c"), (3, HeaderProblem::Unknown("c".into())));
        let duplicate = HeaderProblem::Duplicate {
            name: "alpha".into(),
            first_column: 1,
        };
        assert_eq!(problem("a,b,alpha"), (5, duplicate));
        assert!(matches!(problem("a;b").1, HeaderProblem::Token(_)));
    }
}

//! The one refusal of a text table: where (file, line, column) and what is wrong, displayed as
//! one line `file:line:column: what is wrong and what to fix` that an editor can jump to.

use std::path::{Path, PathBuf};

/// A refusal located in a table's text but not yet tied to a path; the reader attaches the path
/// with [`Refusal::in_file`]. `K` is the reader's own account of what is wrong.
///
/// Line and column are 1-based (the column counts characters, not bytes). Line 0 is the whole
/// file (a problem of no one line: too few rows, a band not covered); column 0 is the whole
/// line (a row out of order, a date that does not exist).
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal<K> {
    pub line: u64,
    pub column: u64,
    pub kind: K,
}

impl<K> Refusal<K> {
    pub fn new(line: u64, column: u64, kind: K) -> Self {
        Self { line, column, kind }
    }

    /// A refusal of the whole line `line`.
    pub fn at_line(line: u64, kind: K) -> Self {
        Self::new(line, 0, kind)
    }

    /// The refusal with the reader's account of it turned into another type.
    pub fn map<L>(self, f: impl FnOnce(K) -> L) -> Refusal<L> {
        Refusal::new(self.line, self.column, f(self.kind))
    }

    /// The refusal in the file `file`, as the caller gave its path.
    pub fn in_file(self, file: &Path) -> TableError<K> {
        TableError {
            file: file.to_path_buf(),
            line: self.line,
            column: self.column,
            kind: self.kind,
        }
    }
}

/// A refused table: the file as the caller gave it (not canonicalized), the 1-based line and
/// character column of [`Refusal`] (0 for the whole file or the whole line) and what is wrong.
/// Displays as `file:line:column: what`, `file:line: what` or `file: what`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}{}: {kind}", crate::text::path(file), place(*line, *column))]
pub struct TableError<K> {
    pub file: PathBuf,
    pub line: u64,
    pub column: u64,
    pub kind: K,
}

/// `:line:column`, `:line` or nothing, as much of the place as is known.
fn place(line: u64, column: u64) -> String {
    match (line, column) {
        (0, _) => String::new(),
        (line, 0) => format!(":{line}"),
        (line, column) => format!(":{line}:{column}"),
    }
}

/// What is wrong, as a sentence, for readers whose refusals carry no more structure than their
/// message (the atmosphere and weather tables).
#[derive(Debug, Clone, PartialEq)]
pub struct Problem(pub String);

impl From<String> for Problem {
    fn from(message: String) -> Self {
        Problem(message)
    }
}

impl From<&str> for Problem {
    fn from(message: &str) -> Self {
        Problem(message.to_owned())
    }
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_place_shows_as_much_as_is_known() {
        let shown = |line, column| {
            Refusal::new(line, column, Problem::from("wrong"))
                .in_file(Path::new("t.csv"))
                .to_string()
        };
        assert_eq!(shown(3, 7), "t.csv:3:7: wrong");
        assert_eq!(shown(3, 0), "t.csv:3: wrong");
        assert_eq!(shown(0, 0), "t.csv: wrong");
    }
}

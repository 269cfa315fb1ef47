//! What the command line says on stdout and stderr besides its results: lines that survive a
//! closed pipe, notes and warnings.

use std::io::Write;

pub(crate) fn print_line(line: std::fmt::Arguments) {
    if let Err(error) = writeln!(std::io::stdout(), "{line}") {
        if error.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("irpol: error: cannot write to stdout: {error}");
        std::process::exit(1);
    }
}

/// Each note on stderr: what irpol did that the user should know, not a problem.
pub(crate) fn note_all(notes: &[String]) {
    for note in notes {
        eprintln!("irpol: note: {note}");
    }
}

/// Each distinct warning once, in order, on stderr.
pub(crate) fn warn_once(warnings: &[String]) {
    let mut seen = std::collections::BTreeSet::new();
    for w in warnings.iter().filter(|w| seen.insert(w.as_str())) {
        eprintln!("irpol: warning: {w}");
    }
}

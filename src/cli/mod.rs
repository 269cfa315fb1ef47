//! Pieces of the command line that are not the library's business: its grammar, what it prints,
//! its progress bars and its interrupt handling.

/// `println!` that treats a closed stdout (`irpol … | head`) as the reader being done, not as a
/// panic.
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::cli::terminal::print_line(format_args!($($arg)*))
    };
}

pub mod allocator;
pub mod args;
pub mod demo;
pub mod fit_summary;
pub mod library;
pub mod progress;
pub mod render_summary;
pub mod signals;
pub mod terminal;

//! (module optics)

//! (module scene)

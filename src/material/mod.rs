//! (module material)

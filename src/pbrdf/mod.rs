//! (module pbrdf)

//! Progress reporting from the library: long work calls a [`Progress`] sink; the binary draws the
//! bars (the library never prints).

/// Receives progress of long work. `begin` announces a stage of `total` steps, `advance` reports
/// finished steps (from any thread), `end` closes the stage. Work done one named item at a time
/// (`irpol fit`'s materials) names the item under way with `message`; a stage that fails calls
/// `abandon` instead of `end`, so what was shown stays for the error that follows.
pub trait Progress: Sync {
    fn begin(&self, _stage: &str, _total: u64) {}
    fn message(&self, _text: &str) {}
    fn advance(&self, _steps: u64) {}
    fn end(&self) {}
    fn abandon(&self) {}
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {}

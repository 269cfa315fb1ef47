//! Progress reporting from the library: long work calls a [`Progress`] sink; the binary draws the
//! bars (the library never prints).

/// Receives progress of long work. `begin` announces a stage of `total` steps, `advance` reports
/// finished steps (from any thread), `end` closes the stage.
pub trait Progress: Sync {
    fn begin(&self, _stage: &str, _total: u64) {}
    fn advance(&self, _steps: u64) {}
    fn end(&self) {}
}

/// Reports nothing.
pub struct Silent;

impl Progress for Silent {}

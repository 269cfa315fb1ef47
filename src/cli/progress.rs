//! Progress bars on stderr for the library's [`Progress`] callbacks: drawn only when stderr is a
//! terminal, so piped or logged runs stay quiet.

use indicatif::{ProgressBar, ProgressStyle};
use irpol::progress::Progress;
use std::io::IsTerminal;
use std::sync::Mutex;

/// A [`Progress`] sink that draws one indicatif bar per stage.
pub struct TerminalProgress {
    bar: Mutex<Option<ProgressBar>>,
    enabled: bool,
    /// Whether the bar counts named items ("fitting ▕…▏ 2/5 paint") instead of a percentage.
    counting: bool,
}

impl TerminalProgress {
    /// Bars with the percentage done and the time taken.
    pub fn new() -> TerminalProgress {
        TerminalProgress {
            bar: Mutex::new(None),
            enabled: std::io::stderr().is_terminal(),
            counting: false,
        }
    }

    /// Bars that count items and name the one under way (`irpol fit`'s materials).
    pub fn counting() -> TerminalProgress {
        TerminalProgress {
            counting: true,
            ..TerminalProgress::new()
        }
    }

    fn template(&self, stage: &str) -> String {
        if self.counting {
            format!("{stage} {{bar:30}} {{pos}}/{{len}} {{msg}}")
        } else {
            format!("{stage} {{bar:40}} {{percent:>3}}% {{elapsed}}")
        }
    }

    fn with_bar(&self, act: impl FnOnce(&ProgressBar)) {
        if let Ok(slot) = self.bar.lock() {
            if let Some(bar) = slot.as_ref() {
                act(bar);
            }
        }
    }

    /// Takes the stage's bar out (it is finished with).
    fn take_bar(&self) -> Option<ProgressBar> {
        self.bar.lock().ok().and_then(|mut slot| slot.take())
    }
}

impl Progress for TerminalProgress {
    fn begin(&self, stage: &str, total: u64) {
        if !self.enabled {
            return;
        }
        let bar = ProgressBar::new(total);
        if let Ok(style) = ProgressStyle::with_template(&self.template(stage)) {
            bar.set_style(style);
        }
        if let Ok(mut slot) = self.bar.lock() {
            *slot = Some(bar);
        }
    }

    fn message(&self, text: &str) {
        self.with_bar(|bar| bar.set_message(text.to_owned()));
    }

    fn advance(&self, steps: u64) {
        self.with_bar(|bar| bar.inc(steps));
    }

    fn end(&self) {
        if let Some(bar) = self.take_bar() {
            bar.finish_and_clear();
        }
    }

    fn abandon(&self) {
        if let Some(bar) = self.take_bar() {
            bar.abandon();
        }
    }
}

//! A spinner on stderr while a stage runs, shown only on a terminal and without `--quiet`.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// A named stage with a spinner; finishing clears it.
pub struct Stage {
    bar: Option<ProgressBar>,
}

impl Stage {
    /// Start a stage; `quiet` or a non-terminal stderr shows nothing.
    pub fn start(quiet: bool, message: impl Into<String>) -> Stage {
        if quiet || !std::io::stderr().is_terminal() {
            return Stage { bar: None };
        }
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} [{elapsed}]")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        bar.set_message(message.into());
        bar.enable_steady_tick(Duration::from_millis(100));
        Stage { bar: Some(bar) }
    }

    /// Change the message of the running stage.
    pub fn set(&self, message: impl Into<String>) {
        if let Some(b) = &self.bar {
            b.set_message(message.into());
        }
    }
}

impl Drop for Stage {
    fn drop(&mut self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

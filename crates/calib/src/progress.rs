//! What a long command is doing, on a terminal: a spinner on stderr with the running phase and
//! the time it has run, fed by [`timings`]. Nothing is drawn where stderr is not a terminal
//! (a pipe, a file, CI), so output that scripts read is unchanged.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::time::Duration;

/// The spinner, or nothing where stderr is not a terminal.
#[derive(Debug)]
pub struct Progress {
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A spinner labelled `command` on stderr if it is a terminal.
    pub fn on_terminal(command: &str) -> Self {
        if !std::io::stderr().is_terminal() {
            return Self { bar: None };
        }
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template("{spinner} {prefix}: {msg} ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_spinner());
        bar.set_style(style);
        bar.set_prefix(command.to_owned());
        bar.enable_steady_tick(Duration::from_millis(200));
        Self { bar: Some(bar) }
    }

    /// The feed for [`timings::record_with`]: each phase's name as it starts.
    pub fn feed(&self) -> Option<timings::OnStart> {
        let bar = self.bar.clone()?;
        Some(Box::new(move |phase: &str| bar.set_message(phase.to_owned())))
    }

    /// Clears the spinner's line.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

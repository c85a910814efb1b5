//! Terminal progress bars (indicatif) behind the library's [`peopletrack::progress`] traits.
//! Only the binary draws; the library reports through the traits.

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use peopletrack::progress::{Progress, Reporter};

/// Bars stacked on stderr, one per session in flight.
pub struct Bars {
    multi: MultiProgress,
}

impl Bars {
    /// Bars drawn on stderr when `visible` (a terminal), hidden otherwise.
    pub fn new(visible: bool) -> Bars {
        let multi = MultiProgress::new();
        if !visible {
            multi.set_draw_target(ProgressDrawTarget::hidden());
        }
        Bars { multi }
    }
}

struct Bar {
    bar: ProgressBar,
    multi: MultiProgress,
}

impl Progress for Bar {
    fn set_length(&self, len: u64) {
        self.bar.set_length(len);
    }
    fn inc(&self, n: u64) {
        self.bar.inc(n);
    }
    fn set_message(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
        self.multi.remove(&self.bar);
    }
}

impl Reporter for Bars {
    fn bar(&self, prefix: &str, unit: &str) -> Box<dyn Progress> {
        let bar = self.multi.add(ProgressBar::new(0));
        let template =
            format!("{{prefix:>24}} [{{bar:30}}] {{pos}}/{{len}} {unit} {{msg}} {{elapsed}}");
        bar.set_style(
            ProgressStyle::with_template(&template)
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_prefix(prefix.to_string());
        Box::new(Bar {
            bar,
            multi: self.multi.clone(),
        })
    }
}

/// A shared reporter for options: bars on stderr when it is a terminal.
pub fn shared(visible: bool) -> peopletrack::progress::SharedReporter {
    Some(std::sync::Arc::new(Bars::new(visible)))
}

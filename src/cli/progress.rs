//! Progress on stderr: an indicatif bar on a terminal, plain lines elsewhere (CI, farms).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

pub struct Progress {
    label: String,
    bar: Option<ProgressBar>,
    plain: bool,
    total: u64,
    done: AtomicU64,
    start: Instant,
    /// Milliseconds since start at which the last plain line was printed.
    last_ms: AtomicU64,
}

impl Progress {
    /// `label` prefixes every line (e.g. the frame being rendered).
    pub fn new(total: u64, quiet: bool, label: &str) -> Self {
        let tty = std::io::stderr().is_terminal();
        let bar = (!quiet && tty).then(|| {
            let b = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template("{bar:40.cyan/blue} {percent:>3}% {msg} eta {eta}")
                    .expect("static template"),
            );
            b.enable_steady_tick(Duration::from_millis(200));
            b
        });
        Self {
            label: if label.is_empty() {
                "render".into()
            } else {
                label.to_string()
            },
            bar,
            plain: !quiet && !tty,
            total,
            done: AtomicU64::new(0),
            start: Instant::now(),
            last_ms: AtomicU64::new(0),
        }
    }

    /// Called once per finished tile from any worker; never blocks a worker except to print.
    pub fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let secs = self.start.elapsed().as_secs_f64();
        let rate = done as f64 / secs.max(1e-9);
        if let Some(b) = &self.bar {
            b.set_position(done);
            b.set_message(format!("{:.2} Msamples/s", rate * 1e-6));
        } else if self.plain {
            let ms = (secs * 1000.0) as u64;
            let last = self.last_ms.load(Ordering::Relaxed);
            if ms >= last + 5000
                && self
                    .last_ms
                    .compare_exchange(last, ms, Ordering::Relaxed, Ordering::Relaxed)
                    .is_ok()
            {
                let eta = (self.total.saturating_sub(done)) as f64 / rate.max(1e-9);
                eprintln!(
                    "{} {:.1}% {:.2} Msamples/s eta {:.0}s",
                    self.label,
                    100.0 * done as f64 / self.total.max(1) as f64,
                    rate * 1e-6,
                    eta
                );
            }
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

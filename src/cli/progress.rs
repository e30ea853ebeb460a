//! Progress on stderr: an indicatif bar on a terminal, plain lines elsewhere (CI, farms).
//!
//! A render with a target error cannot know its sample count in advance: its bar measures the
//! fall of the estimated relMSE in log scale, from the first pass's estimate to the target, and
//! its ETA extrapolates the power law the estimate has followed so far.

use crate::integrator::{Observer, PassReport};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
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
    /// The target relMSE, for renders that have one.
    target: Option<f64>,
    /// (seconds, estimated relMSE) after each pass of a render with a target.
    passes: Mutex<Vec<(f64, f64)>>,
}

/// Steps of the bar of a render with a target error.
const STEPS: u64 = 1000;

impl Progress {
    /// `label` prefixes every line (e.g. the frame being rendered); `target` is the render's
    /// target relMSE, if it has one (then `total` is only its cap).
    pub fn new(total: u64, quiet: bool, label: &str, target: Option<f64>) -> Self {
        let tty = std::io::stderr().is_terminal();
        let bar = (!quiet && tty).then(|| {
            let (len, template) = match target {
                None => (total, "{bar:40.cyan/blue} {percent:>3}% {msg} eta {eta}"),
                Some(_) => (STEPS, "{bar:40.cyan/blue} {msg}"),
            };
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
            b.set_style(ProgressStyle::with_template(template).expect("static template"));
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
            target,
            passes: Mutex::new(Vec::new()),
        }
    }

    /// Called once per finished tile from any worker; never blocks a worker except to print.
    pub fn add(&self, n: u64) {
        let done = self.done.fetch_add(n, Ordering::Relaxed) + n;
        let secs = self.start.elapsed().as_secs_f64();
        let rate = done as f64 / secs.max(1e-9);
        if self.target.is_some() {
            // Lines and the bar's message come from the passes.
            return;
        }
        if let Some(b) = &self.bar {
            b.set_position(done);
            b.set_message(format!("{:.2} Msamples/s", rate * 1e-6));
        } else if self.plain && self.due(secs) {
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

    /// Whether a plain line is due (one per 5 s at most).
    fn due(&self, secs: f64) -> bool {
        let ms = (secs * 1000.0) as u64;
        let last = self.last_ms.load(Ordering::Relaxed);
        ms >= last + 5000
            && self
                .last_ms
                .compare_exchange(last, ms, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok()
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Seconds until the estimate reaches `target`, from a least-squares power law
/// `log E = a − k log t` through the passes so far (the last four, where it is closest to its
/// asymptote); `None` until two passes give a falling estimate.
pub fn eta_to_target(passes: &[(f64, f64)], target: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = passes
        .iter()
        .rev()
        .take(4)
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && e.is_finite())
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let k = -sxy / sxx;
    if !(k.is_finite() && k > 0.05) {
        return None;
    }
    let (t_now, e_now) = *passes.last()?;
    if e_now <= target {
        return Some(0.0);
    }
    // Along the fitted slope from where the estimate is now.
    Some(t_now * ((e_now / target).powf(1.0 / k) - 1.0))
}

impl Observer for Progress {
    fn samples(&self, n: u64) {
        self.add(n);
    }

    fn pass(&self, r: &PassReport) {
        let (Some(target), Some(est)) = (self.target, r.estimate) else {
            return;
        };
        let mut passes = self.passes.lock().unwrap_or_else(|e| e.into_inner());
        passes.push((r.seconds, est));
        let first = passes[0].1;
        let eta = eta_to_target(&passes, target);
        drop(passes);
        let rate = r.samples as f64 / r.seconds.max(1e-9);
        let eta = eta.map_or("?".to_string(), |s| format!("{s:.0}s"));
        let msg = format!(
            "est. relMSE {est:.3e} → {target:.1e}, {:.2} Msamples/s, eta {eta}",
            rate * 1e-6
        );
        if let Some(b) = &self.bar {
            // Log-scale progress from the first estimate to the target.
            let f = if first > target && est < first {
                ((first / est).ln() / (first / target).ln()).clamp(0.0, 1.0)
            } else if est <= target {
                1.0
            } else {
                0.0
            };
            b.set_position((f * STEPS as f64) as u64);
            b.set_message(msg);
        } else if self.plain && (self.due(r.seconds) || est <= target) {
            eprintln!("{} {msg}", self.label);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::eta_to_target;

    #[test]
    fn eta_follows_an_inverse_law() {
        // E = 1 / t: from E = 0.1 at t = 10, E = 0.01 comes at t = 100.
        let passes: Vec<(f64, f64)> = [1.0, 2.0, 5.0, 10.0]
            .iter()
            .map(|&t| (t, 1.0 / t))
            .collect();
        let eta = eta_to_target(&passes, 0.01).unwrap();
        assert!((eta - 90.0).abs() < 1e-6, "{eta}");
        assert_eq!(eta_to_target(&passes[..1], 0.01), None);
        assert_eq!(eta_to_target(&passes, 0.5), Some(0.0));
    }
}

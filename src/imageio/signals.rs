//! SIGINT and SIGTERM: the first asks the render to stop, so the command can write what it
//! has (a still with its true sample count, marked incomplete; a frame series drops the frame
//! in flight); the second removes the temporary files of writes in progress and exits at once
//! with status 128 + the signal's number, as a shell reports a process killed by it.
//!
//! The handler is a thread that waits for the signals (`signal-hook`'s iterator), so nothing
//! beyond setting a flag runs in signal context.

use std::sync::Once;
use std::sync::atomic::{AtomicBool, AtomicI32, Ordering};

/// Set by the first signal; the render loop polls it between tiles.
static STOP: AtomicBool = AtomicBool::new(false);
/// The number of the first signal received (0: none).
static SIGNAL: AtomicI32 = AtomicI32::new(0);

/// The flag the first SIGINT or SIGTERM sets, for [`crate::integrator::RenderOptions::stop`].
pub fn stop_flag() -> &'static AtomicBool {
    &STOP
}

/// The signal that asked the process to stop, if one did: its number and name.
pub fn received() -> Option<(i32, &'static str)> {
    match SIGNAL.load(Ordering::SeqCst) {
        0 => None,
        2 => Some((2, "SIGINT")),
        15 => Some((15, "SIGTERM")),
        n => Some((n, "a signal")),
    }
}

/// Starts handling SIGINT and SIGTERM as the module says (once per process; later calls do
/// nothing). Where signals cannot be handled, they keep their default action.
pub fn install() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGINT, SIGTERM};
            let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else {
                return;
            };
            let _ = std::thread::Builder::new()
                .name("prism-signals".into())
                .spawn(move || {
                    for sig in signals.forever() {
                        // One thread handles them all, so load-then-store cannot race.
                        if STOP.load(Ordering::SeqCst) {
                            super::atomic::remove_in_flight();
                            std::process::exit(128 + sig);
                        }
                        SIGNAL.store(sig, Ordering::SeqCst);
                        STOP.store(true, Ordering::SeqCst);
                    }
                });
        }
    });
}

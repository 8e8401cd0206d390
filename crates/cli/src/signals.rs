//! SIGINT, SIGTERM and SIGHUP (a closed terminal or ssh session, treated like SIGTERM).
//!
//! During `render` and `beam` ([`Mode::Finish`]) the first signal asks the running render to
//! stop ([`tracer::interrupt`]); the command then writes what its completed passes gave (the
//! sidecar says `"interrupted": true` with the samples actually taken) and exits with
//! 128 + the signal number (130 for SIGINT, 143 for SIGTERM, 129 for SIGHUP). A second signal
//! exits at once. During `merge` ([`Mode::Quit`]), which has no passes to keep, the first
//! signal exits at once. Exiting at once removes every temporary output file still being
//! written and the output locks ([`tracer::output::abandon_and_exit`]), so nothing half-written
//! is left behind.

use std::sync::atomic::{AtomicI32, Ordering};

use crate::diag::say;
use anyhow::Context;
use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// The first signal received (0: none).
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// What the first signal does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Stop the render, write the completed passes, then exit (a second signal exits at once).
    Finish,
    /// Exit at once, removing unfinished outputs.
    Quit,
}

/// Installs the handler (a thread that waits for the signals). Commands that do not call this
/// keep the default behaviour: a signal ends them at once.
pub fn install(mode: Mode) -> anyhow::Result<()> {
    let mut signals = Signals::new([SIGINT, SIGTERM, SIGHUP])
        .context("cannot install the SIGINT/SIGTERM/SIGHUP handler")?;
    std::thread::spawn(move || {
        for sig in signals.forever() {
            let first = RECEIVED
                .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst)
                .is_ok();
            if first && mode == Mode::Finish {
                tracer::interrupt::request();
                say!(
                    "\n{}: stopping after writing the completed passes (send it again to quit at once)",
                    name(sig)
                );
            } else {
                say!("{}: quitting; nothing more written", name(sig));
                tracer::output::abandon_and_exit(128 + sig);
            }
        }
    });
    Ok(())
}

/// Makes a write past the file size limit (`ulimit -f`) fail with EFBIG, reported like any
/// write error (the temporary file removed), instead of killing the process with SIGXFSZ and
/// leaving the temporary behind.
pub fn ignore_file_size_signal() {
    // SAFETY: setting a signal's disposition to "ignore" at start-up, before any thread.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
}

/// The signal's name.
pub fn name(sig: i32) -> &'static str {
    match sig {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
        SIGHUP => "SIGHUP",
        _ => "signal",
    }
}

/// The first signal received, if any.
pub fn received() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// The exit status after an interrupt: 128 + the signal number.
pub fn exit_status() -> Option<u8> {
    received().map(|s| u8::try_from(128 + s).unwrap_or(1))
}

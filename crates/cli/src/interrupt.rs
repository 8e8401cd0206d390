//! SIGINT and SIGTERM during `render` and `beam`: the first signal asks the running render to
//! stop ([`tracer::interrupt`]); the command then writes what its completed passes gave (the
//! sidecar says `"interrupted": true` with the samples actually taken) and exits with
//! 128 + the signal number (130 for SIGINT, 143 for SIGTERM). A second signal exits at once,
//! after removing any temporary output file still being written.

use std::sync::atomic::{AtomicI32, Ordering};

use anyhow::Context;
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

/// The first signal received (0: none).
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// Installs the handler (a thread that waits for the signals). Commands that do not call this
/// keep the default behaviour: a signal ends them at once.
pub fn install() -> anyhow::Result<()> {
    let mut signals =
        Signals::new([SIGINT, SIGTERM]).context("cannot install the SIGINT/SIGTERM handler")?;
    std::thread::spawn(move || {
        for sig in signals.forever() {
            if RECEIVED
                .compare_exchange(0, sig, Ordering::SeqCst, Ordering::SeqCst)
                .is_ok()
            {
                tracer::interrupt::request();
                eprintln!(
                    "\n{}: stopping after writing the completed passes (send it again to quit at once)",
                    name(sig)
                );
            } else {
                tracer::output::remove_temporary_files();
                eprintln!("{}: quitting; nothing more written", name(sig));
                std::process::exit(128 + sig);
            }
        }
    });
    Ok(())
}

/// The signal's name.
pub fn name(sig: i32) -> &'static str {
    match sig {
        SIGINT => "SIGINT",
        SIGTERM => "SIGTERM",
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

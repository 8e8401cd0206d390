//! Diagnostics on stderr that never stop the work. `eprintln!` panics when stderr is closed or
//! its reader has gone (`2>&1 | head -c0`: exit 101, the render lost); [`say!`] drops the line
//! instead, and the command goes on to write its files and exit with its own status.

/// `eprintln!` that ignores a failed write.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

pub(crate) use say;

/// Writes a command's result (`text`, a line break added) to standard output. A reader that
/// has gone (`het-bssrdf compare a.exr b.exr | head -1`) took what it wanted: that is not an
/// error (`println!` panicked there, exit 101). Any other failed write is, naming stdout.
pub(crate) fn report(text: &str) -> anyhow::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(anyhow::Error::from(e).context("cannot write to standard output"))
        }
        _ => Ok(()),
    }
}

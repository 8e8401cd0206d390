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

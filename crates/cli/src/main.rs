//! `het-bssrdf`: the command-line front end. Thin: parses arguments, calls the library
//! crates, prints results, maps errors to exit codes.

use std::process::ExitCode;

fn main() -> ExitCode {
    eprintln!("het-bssrdf: not yet implemented");
    ExitCode::from(2)
}

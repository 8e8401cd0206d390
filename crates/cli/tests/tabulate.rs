//! `het-bssrdf tabulate` through the built binary: the file is bit-identical whatever the
//! thread count, is a valid table, and a bad destination fails before any work.

use std::process::Command;

fn tabulate(out: &std::path::Path, threads: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .args([
            "tabulate",
            "--photons",
            "3000",
            "--seed",
            "9",
            "--threads",
            threads,
            "-o",
        ])
        .arg(out)
        .output()
        .expect("run het-bssrdf")
}

#[test]
fn the_table_is_bit_identical_whatever_the_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("one.bin"), dir.path().join("two.bin"));
    for (path, threads) in [(&a, "1"), (&b, "2")] {
        let o = tabulate(path, threads);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let (x, y) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert_eq!(x, y, "thread count changed the table");
    let t = bssrdf_core::tabulated::file::TableData::from_bytes(&x).unwrap();
    assert_eq!((t.photons, t.seed), (3000, 9));
    // No temporary file is left beside the output.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

#[test]
fn an_unwritable_destination_fails_before_the_simulation() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("missing-dir").join("t.bin");
    let o = tabulate(&out, "1");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("missing-dir"));
}

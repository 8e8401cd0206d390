//! Writes the tabulated half-space profile's data file (see `bssrdf_core::tabulated`).
//!
//! `cargo run --release -p bssrdf-core --example tabulate -- OUT [PHOTONS] [SEED] [THREADS]`
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = args
        .get(1)
        .expect("usage: tabulate OUT [PHOTONS] [SEED] [THREADS]");
    let photons: u64 = args
        .get(2)
        .map_or(2_000_000, |s| s.parse().expect("photons"));
    let seed: u64 = args.get(3).map_or(1, |s| s.parse().expect("seed"));
    let threads: usize = args.get(4).map_or(2, |s| s.parse().expect("threads"));
    let start = std::time::Instant::now();
    let data = bssrdf_core::tabulated::file::tabulate(seed, photons, threads, |i| {
        eprintln!(
            "plane {i} done after {:.1} s",
            start.elapsed().as_secs_f64()
        )
    });
    let tmp = format!("{out}.tmp");
    std::fs::write(&tmp, data.to_bytes()).expect("write");
    std::fs::rename(&tmp, out).expect("rename");
    eprintln!("wrote {out} in {:.1} s", start.elapsed().as_secs_f64());
}

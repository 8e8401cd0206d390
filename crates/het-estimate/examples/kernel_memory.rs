//! Memory across many materials: prepares the kernel estimator for 1,000 distinct relative
//! indices η (an artist dragging a slider), estimates one pair with each, keeps only the
//! latest, and prints the resident set size (Linux `/proc/self/statm`) as it goes. The kernel's
//! table (512 KiB per distinct η) belongs to the prepared estimator, so the resident set
//! should stay flat: the target is at most 10 MiB of growth after the first material.
//!
//! Run: `cargo run --release -p het-estimate --example kernel_memory`

use std::time::Instant;

use het_estimate::analytic::{Plane, PlanePoint, StripeField};
use het_estimate::kernel_table::KernelTable;
use het_estimate::pattern::Stripe;
use het_estimate::{Coefficients, Estimator, KernelParams, SplitMix64};

/// The resident set size in bytes, or `None` where `/proc/self/statm` cannot be read.
fn rss_bytes() -> Option<u64> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = statm.split_whitespace().nth(1)?.parse().ok()?;
    // 4 KiB pages: the page size of every Linux target this project builds for.
    Some(pages * 4096)
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1024.0 * 1024.0)
}

fn main() {
    const MATERIALS: usize = 1_000;
    let field = StripeField {
        pattern: Stripe::new(0.5, 0.0),
        values: [Coefficients::grey(0.02, 1.0), Coefficients::grey(0.4, 1.0)],
    };
    let (x_i, x_o) = (PlanePoint::new(0.0, 0.0), PlanePoint::new(0.9, 0.2));
    let estimator = Estimator::Kernel(KernelParams::default());
    let start = Instant::now();
    let mut first = None;
    let mut peak = 0;
    let mut current = None;
    let mut checksum = 0.0;
    for k in 0..MATERIALS {
        // 1,000 distinct η in [1, 3).
        let eta = 1.0 + 2.0 * k as f64 / MATERIALS as f64;
        // Replacing the previous material drops its estimator, and with it its table.
        current = Some(estimator.prepare(0.0, eta).expect("valid material"));
        let prepared = current.as_ref().expect("just set");
        let mut rng = SplitMix64::new(k as u64);
        let est = prepared.estimate(&Plane, &field, &x_i, &x_o, &mut rng);
        checksum += est.coefficients.sigma_a[0];
        let rss = rss_bytes();
        if k == 0 {
            first = rss;
        }
        peak = peak.max(rss.unwrap_or(0));
        if k == 0 || (k + 1) % 100 == 0 {
            println!(
                "{:>5} materials (eta {eta:.3}): RSS {} MiB, live kernel tables {}",
                k + 1,
                rss.map_or("?".into(), |b| format!("{:.1}", mib(b))),
                KernelTable::live_tables()
            );
        }
    }
    drop(current);
    let last = rss_bytes();
    println!(
        "{MATERIALS} distinct eta in {:.1} s (sigma_a checksum {checksum:.6})",
        start.elapsed().as_secs_f64()
    );
    match (first, last) {
        (Some(a), Some(b)) => {
            let growth = mib(peak.saturating_sub(a));
            println!(
                "RSS after the first material {:.1} MiB, peak {:.1} MiB, at the end {:.1} MiB: \
                 growth {growth:.2} MiB (target <= 10 MiB): {}",
                mib(a),
                mib(peak),
                mib(b),
                if growth <= 10.0 { "met" } else { "NOT met" }
            );
        }
        _ => println!("RSS not available on this system (no /proc/self/statm)"),
    }
}

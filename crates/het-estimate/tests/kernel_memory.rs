//! The kernel's tables belong to the prepared estimators (they used to be leaked, 512 KiB per
//! distinct η). A test binary of its own, so that no other test holds a table meanwhile and
//! the counts are exact. The `kernel_memory` example prints the resident set across 1,000 η.

use het_estimate::kernel_table::KernelTable;
use het_estimate::{Estimator, KernelParams};

/// Preparing materials for many distinct η in turn, each replacing the last, keeps exactly one
/// table alive; clones share it; dropping the last holder frees it.
#[test]
fn distinct_eta_keep_one_table_alive() {
    let kernel = Estimator::Kernel(KernelParams::default());
    let mut current = None;
    for k in 0..40 {
        let eta = 1.05 + 0.037 * k as f64;
        current = Some(kernel.prepare(0.0, eta).unwrap());
        assert_eq!(KernelTable::live_tables(), 1, "η {eta}");
    }
    let clone = current.clone();
    assert_eq!(KernelTable::live_tables(), 1, "a clone shares the table");
    drop((current, clone));
    assert_eq!(KernelTable::live_tables(), 0, "freed with the last holder");
    // Other estimators hold no table.
    let _sone = Estimator::Sone(Default::default())
        .prepare(0.0, 1.3)
        .unwrap();
    assert_eq!(KernelTable::live_tables(), 0);
}

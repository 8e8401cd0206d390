//! Memory estimates checked before large allocations: a render's image buffers, a beam map, a
//! mesh's triangles. Work whose estimate exceeds the memory available is refused with the
//! figure ([`TooLarge`]) instead of aborting on a failed allocation or overflowing a size.

use crate::error::TooLarge;

/// Bytes per pixel a render holds at once: the running sums and the pass being accumulated
/// (2 × 3 `f64`), the mean film (3 `f64`), and the encoded outputs with their intermediate
/// buffers (EXR: 3 `f32` twice; PNG: 3 bytes twice).
pub const RENDER_BYTES_PER_PIXEL: f64 = 48.0 + 24.0 + 24.0 + 6.0;

/// Bytes per triangle of a built object: the mesh's indices and vertices (about 12 + 12), the
/// BVH build's boxes and leaf copies (about 32 + 36 + 4) and the CWBVH nodes (about 16).
pub const BYTES_PER_TRIANGLE: f64 = 112.0;

/// Memory available to this process in bytes: `MemAvailable` of `/proc/meminfo` on Linux, else
/// a conservative 16 GiB.
pub fn available_bytes() -> f64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            text.lines()
                .find_map(|l| l.strip_prefix("MemAvailable:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        })
        .map(|kb| kb * 1024.0)
        .unwrap_or(16.0 * 1024.0 * 1024.0 * 1024.0)
}

/// Refuses `what` when `bytes` exceeds the memory available.
pub fn check(what: impl FnOnce() -> String, bytes: f64) -> Result<(), TooLarge> {
    let available = available_bytes();
    if bytes.is_finite() && bytes <= available {
        Ok(())
    } else {
        Err(TooLarge {
            what: what(),
            bytes,
            available,
        })
    }
}

/// [`check`] for a `width × height` render (computed in `f64`: no overflow).
pub fn check_render(width: u32, height: u32) -> Result<(), TooLarge> {
    check(
        || format!("a {width}x{height} render"),
        f64::from(width) * f64::from(height) * RENDER_BYTES_PER_PIXEL,
    )
}

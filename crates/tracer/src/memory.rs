//! Memory estimates checked before large allocations: a render's image buffers, a beam map, a
//! mesh's triangles, a decoded texture. Work whose estimate exceeds the memory this process
//! may still allocate is refused with the figure ([`TooLarge`]) instead of aborting on a
//! failed allocation or overflowing a size.
//!
//! The memory a process may still allocate is the smallest of ([`headroom`]):
//! - `MemAvailable` of `/proc/meminfo` (the machine's free and reclaimable memory);
//! - `RLIMIT_AS` (`ulimit -v`) minus the address space already mapped (`VmSize` of
//!   `/proc/self/status`);
//! - `RLIMIT_DATA` (`ulimit -d`) minus the data segment in use (`VmData`);
//! - for the process's cgroup and each of its ancestors, cgroup v2 `memory.max` minus
//!   `memory.current` (or cgroup v1 `memory.limit_in_bytes` minus `memory.usage_in_bytes`):
//!   the limit a Slurm job, a Kubernetes pod or a systemd unit runs under.
//!
//! Off Linux, or when none of these can be read, a conservative 16 GiB stands for them.

use std::path::{Path, PathBuf};

use crate::error::TooLarge;

/// Bytes per pixel a render holds at once: the running sums and the pass being accumulated
/// (2 × 3 `f64`), the mean film (3 `f64`), and the encoded outputs with their intermediate
/// buffers (EXR: 3 `f32` twice; PNG: 3 bytes twice).
pub const RENDER_BYTES_PER_PIXEL: f64 = 48.0 + 24.0 + 24.0 + 6.0;

/// Bytes per triangle of a built object: the mesh's indices and vertices (about 12 + 12), the
/// BVH build's boxes and leaf copies (about 32 + 36 + 4) and the CWBVH nodes (about 16).
pub const BYTES_PER_TRIANGLE: f64 = 112.0;

/// Bytes per texel of a decoded texture: 3 `f32`.
pub const TEXTURE_BYTES_PER_TEXEL: f64 = 12.0;

/// Bytes per texel of a texture's summed-area table (3 `f64` per table entry, one more row
/// and column than the texture; see [`crate::field::area_table`]), built by Sone's
/// prefiltered averages ([`area_table_bytes`]).
pub const AREA_TABLE_BYTES_PER_TEXEL: f64 = 24.0;

/// Used when no limit can be read.
const FALLBACK_BYTES: f64 = 16.0 * 1024.0 * 1024.0 * 1024.0;

/// How much memory this process may still allocate, and which limit says so.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Headroom {
    /// Bytes.
    pub bytes: f64,
    /// The limit that gives the figure, in words (`"MemAvailable"`, `"RLIMIT_AS (ulimit
    /// -v)"`, …).
    pub limit: &'static str,
}

/// The smallest of the limits in the module docs.
pub fn headroom() -> Headroom {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let candidates = [
        std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| kib_field(&t, "MemAvailable:"))
            .map(|b| Headroom {
                bytes: b,
                limit: "MemAvailable",
            }),
        rlimit_headroom(Resource::AddressSpace, &status),
        rlimit_headroom(Resource::Data, &status),
        std::fs::read_to_string("/proc/self/cgroup")
            .ok()
            .and_then(|t| cgroup_headroom(&t, Path::new("/sys/fs/cgroup"))),
    ];
    candidates
        .into_iter()
        .flatten()
        .min_by(|a, b| a.bytes.total_cmp(&b.bytes))
        .unwrap_or(Headroom {
            bytes: FALLBACK_BYTES,
            limit: "an assumed 16 GiB (no limit could be read)",
        })
}

/// Memory this process may still allocate, in bytes ([`headroom`]).
pub fn available_bytes() -> f64 {
    headroom().bytes
}

/// The value in kB of the line `name  N kB` of a `/proc` file, in bytes.
fn kib_field(text: &str, name: &str) -> Option<f64> {
    text.lines()
        .find_map(|l| l.strip_prefix(name))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map(|kb| kb * 1024.0)
}

/// The two resource limits on allocation.
#[derive(Debug, Clone, Copy)]
enum Resource {
    /// `RLIMIT_AS`: the address space.
    AddressSpace,
    /// `RLIMIT_DATA`: the data segment (heap and private mappings).
    Data,
}

/// The soft limit of `resource` minus what is in use (`status`: `/proc/self/status`); `None`
/// when unlimited or unreadable.
fn rlimit_headroom(resource: Resource, status: &str) -> Option<Headroom> {
    let (which, used, limit) = match resource {
        Resource::AddressSpace => (libc::RLIMIT_AS, "VmSize:", "RLIMIT_AS (ulimit -v)"),
        Resource::Data => (libc::RLIMIT_DATA, "VmData:", "RLIMIT_DATA (ulimit -d)"),
    };
    let mut rl = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one `rlimit` through a valid pointer.
    if unsafe { libc::getrlimit(which, &mut rl) } != 0 || rl.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    let in_use = kib_field(status, used).unwrap_or(0.0);
    Some(Headroom {
        bytes: (rl.rlim_cur as f64 - in_use).max(0.0),
        limit,
    })
}

/// The tightest cgroup memory limit of this process: `cgroup` is the text of
/// `/proc/self/cgroup`, `root` the cgroup file system's mount point (`/sys/fs/cgroup`). For
/// cgroup v2 (`0::/path`) every directory from `root/path` up to `root` is read; for v1, the
/// `memory` controller's directory and its ancestors.
fn cgroup_headroom(cgroup: &str, root: &Path) -> Option<Headroom> {
    let mut best: Option<Headroom> = None;
    let mut consider = |h: Headroom| {
        if best.is_none_or(|b| h.bytes < b.bytes) {
            best = Some(h);
        }
    };
    for line in cgroup.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(_id), Some(controllers), Some(path)) = (parts.next(), parts.next(), parts.next())
        else {
            continue;
        };
        let rel = path.trim_start_matches('/');
        let (base, max_file, used_file, limit) = if controllers.is_empty() {
            (
                root.to_path_buf(),
                "memory.max",
                "memory.current",
                "cgroup memory.max",
            )
        } else if controllers.split(',').any(|c| c == "memory") {
            (
                root.join("memory"),
                "memory.limit_in_bytes",
                "memory.usage_in_bytes",
                "cgroup memory.limit_in_bytes",
            )
        } else {
            continue;
        };
        let leaf = if rel.is_empty() {
            base.clone()
        } else {
            base.join(rel)
        };
        for dir in leaf.ancestors().take_while(|d| d.starts_with(&base)) {
            if let Some(bytes) = cgroup_dir_headroom(dir, max_file, used_file) {
                consider(Headroom { bytes, limit });
            }
        }
    }
    best
}

/// `max_file − used_file` in `dir`; `None` when the limit is `max` (or a v1 "unlimited" of
/// 2^63 rounded to pages) or a file cannot be read.
fn cgroup_dir_headroom(dir: &Path, max_file: &str, used_file: &str) -> Option<f64> {
    let read = |name: &str| -> Option<String> {
        let p: PathBuf = dir.join(name);
        std::fs::read_to_string(p).ok()
    };
    let max: u64 = read(max_file)?.trim().parse().ok()?;
    if max >= 1 << 62 {
        return None;
    }
    let used: u64 = read(used_file)
        .and_then(|t| t.trim().parse().ok())
        .unwrap_or(0);
    Some(max.saturating_sub(used) as f64)
}

/// Refuses `what` when `bytes` exceeds the memory this process may still allocate
/// ([`headroom`]).
pub fn check(what: impl FnOnce() -> String, bytes: f64) -> Result<(), TooLarge> {
    check_within(headroom(), what, bytes)
}

/// [`check`] against a headroom read before (for many checks in a row: reading the limits
/// takes several file reads).
pub fn check_within(
    room: Headroom,
    what: impl FnOnce() -> String,
    bytes: f64,
) -> Result<(), TooLarge> {
    if bytes.is_finite() && bytes <= room.bytes {
        Ok(())
    } else {
        Err(TooLarge {
            what: what(),
            bytes,
            available: room.bytes,
            limit: room.limit,
        })
    }
}

/// [`check`] for a `width × height` render (computed in `f64`: no overflow), plus
/// `table_bytes` of tables the render builds before its first sample (summed-area tables of
/// its textures).
pub fn check_render(width: u32, height: u32, table_bytes: f64) -> Result<(), TooLarge> {
    check(
        || {
            if table_bytes > 0.0 {
                format!("a {width}x{height} render with its textures' summed-area tables")
            } else {
                format!("a {width}x{height} render")
            }
        },
        f64::from(width) * f64::from(height) * RENDER_BYTES_PER_PIXEL + table_bytes,
    )
}

/// Bytes of the summed-area tables a render of `scene` by `method` builds while it is prepared
/// (Sone with prefiltered averaging: one per image texture of a translucent material, each
/// counted once however many materials share it).
pub fn area_table_bytes(scene: &crate::scene::Scene, method: crate::integrator::Method) -> f64 {
    let crate::integrator::Method::Bssrdf { estimator, .. } = method else {
        return 0.0;
    };
    if !estimator.reads_region_averages() {
        return 0.0;
    }
    let mut seen = std::collections::HashSet::new();
    scene
        .translucent_objects()
        .flat_map(|(_, t)| t.medium.area_table_textures())
        .filter(|t| seen.insert(std::sync::Arc::as_ptr(t)))
        .map(|t| {
            (f64::from(t.width) + 1.0) * (f64::from(t.height) + 1.0) * AREA_TABLE_BYTES_PER_TEXEL
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cgroup_limits_are_read_up_the_hierarchy() {
        let root = tempfile::tempdir().unwrap();
        let r = root.path();
        let job = r.join("slurm/job_7/step_0");
        std::fs::create_dir_all(&job).unwrap();
        let write = |dir: &Path, max: &str, current: &str| {
            std::fs::write(dir.join("memory.max"), max).unwrap();
            std::fs::write(dir.join("memory.current"), current).unwrap();
        };
        write(&job, "max\n", "100\n");
        write(&r.join("slurm/job_7"), "4096\n", "1000\n");
        write(&r.join("slurm"), "1000000\n", "10\n");
        write(r, "max\n", "5\n");
        let h = cgroup_headroom("0::/slurm/job_7/step_0\n", r).unwrap();
        assert_eq!(h.bytes, 3096.0);
        assert_eq!(h.limit, "cgroup memory.max");
        // No limit anywhere.
        assert_eq!(
            cgroup_headroom("0::/\n", &r.join("slurm/job_7/step_0")),
            None
        );
        // cgroup v1: the memory controller's directory.
        let v1 = r.join("memory/kube/pod");
        std::fs::create_dir_all(&v1).unwrap();
        std::fs::write(v1.join("memory.limit_in_bytes"), "2000").unwrap();
        std::fs::write(v1.join("memory.usage_in_bytes"), "500").unwrap();
        std::fs::write(
            r.join("memory/memory.limit_in_bytes"),
            "9223372036854771712",
        )
        .unwrap();
        let h = cgroup_headroom("4:cpu,cpuacct:/kube\n5:memory:/kube/pod\n", r).unwrap();
        assert_eq!(h.bytes, 1500.0);
    }

    #[test]
    fn the_headroom_is_positive_and_at_most_the_machines() {
        let h = headroom();
        assert!(h.bytes.is_finite() && h.bytes >= 0.0, "{h:?}");
        let mem = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|t| kib_field(&t, "MemAvailable:"));
        if let Some(m) = mem {
            // MemAvailable moves between the two reads; allow 1 GiB of drift.
            assert!(h.bytes <= m + 1024.0 * 1024.0 * 1024.0, "{h:?} vs {m}");
        }
    }
}

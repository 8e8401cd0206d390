//! Output writers (EXR, PNG preview, grey EXR maps, JSON sidecars) and EXR reading.
//!
//! Every writer is atomic: the file is encoded in memory, written to a temporary file in the
//! destination directory (`.<name>.<pid>.<n>.tmp`) and renamed into place. On any error the
//! temporary file is removed and nothing is left behind; an existing file at the destination is
//! replaced only on success. Errors name the path. A symbolic link at the destination is written
//! through (its target gets the bytes); a device, FIFO or socket is refused, never replaced.
//! [`OutputSet`] commits several files (EXR, PNG, JSON) together or not at all, and
//! [`remove_temporary_files`] lets an interrupted process remove its unfinished temporaries
//! ([`abandon_and_exit`] also removes its locks and exits).
//!
//! **Sets and runs.** An [`OutputLock`] (an advisory `flock` on `.<name>.lock` beside the main
//! file) makes one run at a time the writer of an output set: a second run is refused
//! ([`OutputError::Busy`]) instead of mixing its files with the first one's. The lock holder
//! removes the temporaries a killed run left for the set ([`remove_stale_temporaries`]).
//! [`check_not_inputs`] refuses an output that is one of the run's inputs (same file, however
//! reached).

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use bssrdf_core::Rgb;

use crate::error::OutputError;
use crate::film::Film;

static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Temporary files being written right now, so that an interrupted process can remove them
/// ([`remove_temporary_files`]) before it exits.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(|e| e.into_inner())
}

/// Lock files of the [`OutputLock`]s this process holds, so that [`abandon_and_exit`] can
/// remove them.
static LOCKS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn locks() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LOCKS.lock().unwrap_or_else(|e| e.into_inner())
}

/// Removes every temporary file an atomic write of this process has not finished; for a
/// signal handler that is about to exit the process. Returns how many were removed.
pub fn remove_temporary_files() -> usize {
    let mut list = pending();
    let n = list.iter().filter(|p| fs::remove_file(p).is_ok()).count();
    list.clear();
    n
}

/// Removes this process's unfinished temporary files and its lock files, then exits with
/// `code`, all while holding the registry of temporaries: no other thread can start a new one
/// in between (a write creates its temporary under the same lock). For a signal handler.
pub fn abandon_and_exit(code: i32) -> ! {
    let mut list = pending();
    for p in list.iter() {
        let _ = fs::remove_file(p);
    }
    list.clear();
    for p in locks().iter() {
        let _ = fs::remove_file(p);
    }
    std::process::exit(code)
}

/// The name of the temporary file of a write to `dest` (see the module docs):
/// `.<name>.<pid>.<n>.tmp` beside it.
fn temporary_name(dest: &Path) -> PathBuf {
    let name = dest.file_name().unwrap_or_default().to_string_lossy();
    parent_dir(dest).join(format!(
        ".{name}.{}.{}.tmp",
        std::process::id(),
        TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Removes the temporary files other processes left for the output `path` (its target when a
/// symbolic link): `.<name>.<pid>.<n>.tmp` of any process but this one, which a run killed
/// while writing leaves behind. Call it only while holding the set's [`OutputLock`]: then no
/// other run is writing them. Returns how many were removed.
pub fn remove_stale_temporaries(path: &Path) -> usize {
    let Ok(dest) = resolve_output(path) else {
        return 0;
    };
    let Some(name) = dest.file_name().map(|n| n.to_string_lossy().into_owned()) else {
        return 0;
    };
    let prefix = format!(".{name}.");
    let ours = format!(".{name}.{}.", std::process::id());
    let Ok(entries) = fs::read_dir(parent_dir(&dest)) else {
        return 0;
    };
    entries
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            let Some(middle) = n
                .strip_prefix(&prefix)
                .and_then(|rest| rest.strip_suffix(".tmp"))
            else {
                return false;
            };
            // `<pid>.<n>`, both numbers, and not this process's.
            let numbers = middle
                .split_once('.')
                .is_some_and(|(a, b)| a.parse::<u32>().is_ok() && b.parse::<u64>().is_ok());
            numbers && !n.starts_with(&ours) && e.file_type().is_ok_and(|t| t.is_file())
        })
        .filter(|e| fs::remove_file(e.path()).is_ok())
        .count()
}

/// The lock of an output set, held from before a run's work until its last file is written:
/// an exclusive `flock` on `.<name>.lock` beside the set's main file (its target when a
/// symbolic link), which holds the owner's pid and host for the message of a refused run.
/// Released, and its file removed, when dropped or by [`abandon_and_exit`]; the kernel releases
/// a killed process's lock, and the next run reuses the file.
#[derive(Debug)]
pub struct OutputLock {
    /// Held open: closing it releases the lock.
    _file: fs::File,
    path: PathBuf,
    /// False when the file system does not support locks (some network file systems): the set
    /// is then written unlocked.
    held: bool,
}

impl OutputLock {
    /// Takes the lock of the set whose main file is `path`, or fails with
    /// [`OutputError::Busy`] when another process holds it.
    pub fn acquire(path: &Path) -> Result<OutputLock, OutputError> {
        use std::os::fd::AsRawFd;
        use std::os::unix::fs::MetadataExt;
        let dest = resolve_output(path)?;
        let name = dest
            .file_name()
            .expect("resolve_output checks the file name")
            .to_string_lossy();
        let lock_path = parent_dir(&dest).join(format!(".{name}.lock"));
        let io = |action, source| OutputError::Io {
            path: path.to_path_buf(),
            action,
            source,
        };
        loop {
            let mut file = fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&lock_path)
                .map_err(|e| io("create the lock file of", e))?;
            // SAFETY: flock on a descriptor this function owns.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                let e = std::io::Error::last_os_error();
                let unsupported = [libc::ENOLCK, libc::EOPNOTSUPP, libc::ENOSYS];
                if e.raw_os_error().is_some_and(|c| unsupported.contains(&c)) {
                    locks().push(lock_path.clone());
                    return Ok(OutputLock {
                        _file: file,
                        path: lock_path,
                        held: false,
                    });
                }
                if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
                    let holder = fs::read_to_string(&lock_path)
                        .ok()
                        .map(|t| t.trim().to_string())
                        .filter(|t| !t.is_empty())
                        .unwrap_or_else(|| "a process".to_string());
                    return Err(OutputError::Busy {
                        path: path.to_path_buf(),
                        holder,
                    });
                }
                return Err(io("lock", e));
            }
            // The holder before us may have removed the file after we opened it (and another
            // run created a new one): our lock is then on a file nobody else will see.
            let ours = file.metadata().map(|m| (m.dev(), m.ino()));
            let named = fs::metadata(&lock_path).map(|m| (m.dev(), m.ino()));
            match (ours, named) {
                (Ok(a), Ok(b)) if a == b => {}
                _ => continue,
            }
            let host = fs::read_to_string("/proc/sys/kernel/hostname")
                .map(|h| h.trim().to_string())
                .unwrap_or_default();
            let who = format!("pid {} on {host}", std::process::id());
            let _ = file.set_len(0);
            let _ = file.write_all(who.as_bytes());
            locks().push(lock_path.clone());
            return Ok(OutputLock {
                _file: file,
                path: lock_path,
                held: true,
            });
        }
    }

    /// False when the file system refused to lock (`ENOLCK`, `EOPNOTSUPP`): the set is written
    /// as before locks, and another run writing it would not be seen.
    pub fn is_held(&self) -> bool {
        self.held
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        // Removed before it is unlocked (when the file closes, after this): a run that opened
        // this file meanwhile then sees it gone and opens a new one.
        let _ = fs::remove_file(&self.path);
        locks().retain(|p| p != &self.path);
    }
}

/// Refuses any of `outputs` that is the same file as one of `inputs` (compared by device and
/// inode, so symbolic links, hard links and other spellings of a path are caught); outputs and
/// inputs that do not exist are skipped.
pub fn check_not_inputs<'a>(
    outputs: impl IntoIterator<Item = &'a Path>,
    inputs: &[&Path],
) -> Result<(), OutputError> {
    use std::os::unix::fs::MetadataExt;
    let id = |p: &Path| fs::metadata(p).ok().map(|m| (m.dev(), m.ino()));
    let inputs: Vec<_> = inputs.iter().filter_map(|p| Some((id(p)?, *p))).collect();
    for out in outputs {
        if let Some(o) = id(out)
            && let Some((_, input)) = inputs.iter().find(|(i, _)| *i == o)
        {
            return Err(OutputError::IsInput {
                path: out.to_path_buf(),
                input: input.to_path_buf(),
            });
        }
    }
    Ok(())
}

/// What kind of filesystem object something that is not a regular file is, in words
/// (`"directory"`, `"character device"`, `"FIFO"`…).
pub fn file_kind(ft: &fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if ft.is_dir() {
        "directory"
    } else if ft.is_char_device() {
        "character device"
    } else if ft.is_block_device() {
        "block device"
    } else if ft.is_fifo() {
        "FIFO"
    } else if ft.is_socket() {
        "socket"
    } else {
        "special file"
    }
}

/// The directory that holds `path` (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Where the bytes written to `path` should go, checked without writing anything:
/// - a missing path or a regular file: `path` itself;
/// - a symbolic link: its final target (written through, the link is kept), checked the same
///   way;
/// - a directory, a device, a FIFO or a socket: an error (never replaced by a file);
/// - a missing parent directory, or a parent that is a file: an error saying which.
pub fn resolve_output(path: &Path) -> Result<PathBuf, OutputError> {
    let mut target = path.to_path_buf();
    for _ in 0..40 {
        match fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = fs::read_link(&target).map_err(|source| OutputError::Io {
                    path: path.to_path_buf(),
                    action: "read the symbolic link",
                    source,
                })?;
                target = parent_dir(&target).join(link);
                continue;
            }
            Ok(m) if m.is_dir() => {
                return Err(OutputError::IsDirectory {
                    path: path.to_path_buf(),
                });
            }
            Ok(m) if !m.is_file() => {
                return Err(OutputError::NotRegular {
                    path: path.to_path_buf(),
                    kind: file_kind(&m.file_type()),
                });
            }
            Ok(_) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) if e.raw_os_error() == Some(20) => {
                // ENOTDIR: a component of the parent is a file; found below.
            }
            Err(source) => {
                return Err(OutputError::Io {
                    path: path.to_path_buf(),
                    action: "inspect",
                    source,
                });
            }
        }
        if target.file_name().is_none() {
            return Err(OutputError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let dir = parent_dir(&target);
        if !dir.is_dir() {
            let file_parent = dir.ancestors().find(|a| a.is_file()).map(Path::to_path_buf);
            return Err(match file_parent {
                Some(parent) => OutputError::ParentIsFile {
                    path: path.to_path_buf(),
                    parent,
                },
                None => OutputError::MissingDirectory {
                    path: path.to_path_buf(),
                    dir,
                },
            });
        }
        return Ok(target);
    }
    Err(OutputError::NotRegular {
        path: path.to_path_buf(),
        kind: "chain of more than 40 symbolic links",
    })
}

/// A temporary file written beside its destination and not yet renamed into place; removed
/// when dropped unless committed.
struct Staged {
    tmp: PathBuf,
    dest: PathBuf,
    /// The path the caller asked for (named in errors).
    path: PathBuf,
}

impl Staged {
    /// Writes `bytes` to a new temporary file beside `path`'s target (see [`resolve_output`]).
    fn write(path: &Path, bytes: &[u8]) -> Result<Staged, OutputError> {
        let dest = resolve_output(path)?;
        let tmp = temporary_name(&dest);
        let io = |action, source| OutputError::Io {
            path: path.to_path_buf(),
            action,
            source,
        };
        // Created and registered under the registry's lock, so that [`abandon_and_exit`]
        // sees every temporary file that exists.
        let mut f = {
            let mut list = pending();
            let f = fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&tmp)
                .map_err(|e| io("create a temporary file for", e))?;
            list.push(tmp.clone());
            f
        };
        let staged = Staged {
            tmp,
            dest,
            path: path.to_path_buf(),
        };
        f.write_all(bytes).map_err(|e| io("write", e))?;
        f.sync_all().map_err(|e| io("flush", e))?;
        Ok(staged)
    }

    /// Renames the temporary file into place.
    fn commit(self) -> Result<(), OutputError> {
        let result = fs::rename(&self.tmp, &self.dest).map_err(|source| OutputError::Io {
            path: self.path.clone(),
            action: "rename into place",
            source,
        });
        if result.is_ok() {
            pending().retain(|p| p != &self.tmp);
        }
        // On success the temporary name no longer exists and Drop's removal is a no-op.
        result
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.tmp);
        pending().retain(|p| p != &self.tmp);
    }
}

/// Writes `bytes` to `path` atomically (see the module docs). A symbolic link is written
/// through (its target is replaced, the link kept); a directory, device, FIFO or socket is
/// refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), OutputError> {
    Staged::write(path, bytes)?.commit()
}

/// Files that belong together (an image, its preview and its sidecar), written all or none:
/// every file is encoded in memory, then every one is written to its temporary name (smallest
/// first), and only when all of them are on disk are they renamed into place. A failure before
/// the renames (a full disk, a bad destination) leaves none of them and no temporary file.
#[derive(Debug, Default)]
pub struct OutputSet {
    files: Vec<(PathBuf, Vec<u8>)>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a file.
    pub fn add(&mut self, path: &Path, bytes: Vec<u8>) {
        self.files.push((path.to_path_buf(), bytes));
    }

    /// Checks every destination ([`resolve_output`]) without writing anything.
    pub fn check_paths<'a>(paths: impl IntoIterator<Item = &'a Path>) -> Result<(), OutputError> {
        paths
            .into_iter()
            .try_for_each(|p| resolve_output(p).map(drop))
    }

    /// Writes the set (see the type's docs).
    pub fn commit(mut self) -> Result<(), OutputError> {
        Self::check_paths(self.files.iter().map(|(p, _)| p.as_path()))?;
        self.files.sort_by_key(|(_, b)| b.len());
        let staged = self
            .files
            .iter()
            .map(|(p, b)| Staged::write(p, b))
            .collect::<Result<Vec<_>, _>>()?;
        staged.into_iter().try_for_each(Staged::commit)
    }
}

/// Writes a pretty-printed JSON sidecar atomically.
pub fn write_json(value: &serde_json::Value, path: &Path) -> Result<(), OutputError> {
    write_atomic(path, &json_bytes(value, path)?)
}

/// The bytes [`write_json`] writes (`path` is named in errors only).
pub fn json_bytes(value: &serde_json::Value, path: &Path) -> Result<Vec<u8>, OutputError> {
    let mut s = serde_json::to_string_pretty(value).map_err(|e| OutputError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    s.push('\n');
    Ok(s.into_bytes())
}

/// The sRGB transfer function (sRGB: IEC 61966-2-1): linear `[0, 1]` → encoded `[0, 1]`.
#[inline]
pub fn srgb_encode(linear: f64) -> f64 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function: encoded `[0, 1]` → linear `[0, 1]`.
#[inline]
pub fn srgb_decode(encoded: f64) -> f64 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// The 8-bit sRGB preview value of a linear value after exposure: `x · 2^stops`, sRGB
/// encoded, clamped to `[0, 1]`, rounded (NaN → 0).
#[inline]
pub fn preview_byte(linear: f64, exposure_stops: f64) -> u8 {
    let v = srgb_encode(linear * exposure_stops.exp2());
    if v.is_nan() {
        0
    } else {
        (v.clamp(0.0, 1.0) * 255.0).round() as u8
    }
}

/// Writes the film as an 8-bit sRGB PNG preview: exposure `2^exposure_stops`, then the sRGB
/// curve (applied here, not by the encoder), then clamping.
pub fn write_png(film: &Film, path: &Path, exposure_stops: f64) -> Result<(), OutputError> {
    write_atomic(path, &png_bytes(film, path, exposure_stops)?)
}

/// The bytes [`write_png`] writes (`path` is named in errors only).
pub fn png_bytes(film: &Film, path: &Path, exposure_stops: f64) -> Result<Vec<u8>, OutputError> {
    #[cfg(feature = "png")]
    {
        let mut buf = Vec::with_capacity(film.pixels.len() * 3);
        for p in &film.pixels {
            for c in 0..3 {
                buf.push(preview_byte(p[c], exposure_stops));
            }
        }
        let img = image::RgbImage::from_raw(film.width, film.height, buf).ok_or_else(|| {
            OutputError::Encode {
                path: path.to_path_buf(),
                message: "film size does not match its pixel count".into(),
            }
        })?;
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png)
            .map_err(|e| OutputError::Encode {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        Ok(bytes.into_inner())
    }
    #[cfg(not(feature = "png"))]
    {
        let _ = (film, exposure_stops);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "png",
        })
    }
}

/// A custom attribute of an EXR header, as pbrt-v4 records render metadata
/// (`samplesPerPixel`, `seed`, …).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum ExrAttribute {
    /// A 32-bit integer (`int`).
    Int(i32),
    /// A 32-bit float (`float`).
    Float(f32),
    /// Latin-1 text (`string`).
    Text(String),
}

/// Writes the film as an EXR with three `f32` channels R, G, B.
pub fn write_exr(film: &Film, path: &Path) -> Result<(), OutputError> {
    write_exr_with_attributes(film, path, &[])
}

/// The EXR header attribute (a string) in which [`write_exr_with_attributes`] records its
/// metadata: `name=value` pairs joined by `; `.
pub const METADATA_ATTRIBUTE: &str = "hetBssrdf";

/// [`write_exr`] with render metadata in the header (names and values must be Latin-1), as
/// pbrt-v4 records its own; they are joined into the one string attribute
/// [`METADATA_ATTRIBUTE`] so that the file's bytes stay reproducible. Written atomically.
pub fn write_exr_with_attributes(
    film: &Film,
    path: &Path,
    attributes: &[(&str, ExrAttribute)],
) -> Result<(), OutputError> {
    write_atomic(path, &exr_bytes(film, path, attributes)?)
}

/// The bytes [`write_exr_with_attributes`] writes (`path` is named in errors only).
pub fn exr_bytes(
    film: &Film,
    path: &Path,
    attributes: &[(&str, ExrAttribute)],
) -> Result<Vec<u8>, OutputError> {
    #[cfg(feature = "exr")]
    {
        use exr::meta::attribute::{AttributeValue, Text};
        use exr::prelude::*;
        check_size(film.width, film.height, film.pixels.len(), path)?;
        let w = film.width as usize;
        let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
            let p = film.pixels[y * w + x];
            (p[0] as f32, p[1] as f32, p[2] as f32)
        });
        let mut image = Image::from_encoded_channels(
            (film.width as usize, film.height as usize),
            fixed_order(),
            channels,
        );
        if !attributes.is_empty() {
            // One attribute holding every pair, in the caller's order: the EXR crate keeps
            // custom attributes in a hash map whose order changes from process to process, so
            // several attributes would make the file's bytes differ between identical renders.
            let joined = attributes
                .iter()
                .map(|(name, value)| match value {
                    ExrAttribute::Int(v) => format!("{name}={v}"),
                    ExrAttribute::Float(v) => format!("{name}={v}"),
                    ExrAttribute::Text(v) => format!("{name}={v}"),
                })
                .collect::<Vec<_>>()
                .join("; ");
            let text = Text::new_or_none(&joined).ok_or_else(|| OutputError::Encode {
                path: path.to_path_buf(),
                message: format!("EXR header text must be Latin-1: `{joined}`"),
            })?;
            image
                .layer_data
                .attributes
                .other
                .insert(Text::from(METADATA_ATTRIBUTE), AttributeValue::Text(text));
        }
        encode_exr(path, |bytes| image.write().to_buffered(bytes))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = (film, attributes);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "exr",
        })
    }
}

/// Writes a single-channel map (e.g. the beam experiment's exitance) as an EXR with one `f32`
/// channel `Y`; `values` is row-major, row 0 at the top.
pub fn write_grey_exr(
    width: u32,
    height: u32,
    values: &[f64],
    path: &Path,
) -> Result<(), OutputError> {
    write_atomic(path, &grey_exr_bytes(width, height, values, path)?)
}

/// The bytes [`write_grey_exr`] writes (`path` is named in errors only).
pub fn grey_exr_bytes(
    width: u32,
    height: u32,
    values: &[f64],
    path: &Path,
) -> Result<Vec<u8>, OutputError> {
    #[cfg(feature = "exr")]
    {
        use exr::prelude::*;
        check_size(width, height, values.len(), path)?;
        let w = width as usize;
        let channels = SpecificChannels::build()
            .with_channel("Y")
            .with_pixel_fn(|Vec2(x, y): Vec2<usize>| (values[y * w + x] as f32,));
        let image = Image::from_encoded_channels(
            (width as usize, height as usize),
            fixed_order(),
            channels,
        );
        encode_exr(path, |bytes| image.write().to_buffered(bytes))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = (width, height, values);
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "exr",
        })
    }
}

/// The encoding of every EXR written: the `exr` crate's default compression and tiling, with
/// chunks in increasing-y order. The default (unspecified order, declared RANDOM_Y) writes
/// chunks as the compressing threads finish them, so the file's bytes would depend on the
/// thread count and timing; in a fixed order they are reproducible.
#[cfg(feature = "exr")]
fn fixed_order() -> exr::prelude::Encoding {
    exr::prelude::Encoding {
        line_order: exr::prelude::LineOrder::Increasing,
        ..exr::prelude::Encoding::default()
    }
}

/// Encodes an EXR into memory with `write` (`path` is named in errors).
#[cfg(feature = "exr")]
fn encode_exr(
    path: &Path,
    write: impl FnOnce(&mut std::io::Cursor<Vec<u8>>) -> exr::error::UnitResult,
) -> Result<Vec<u8>, OutputError> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    write(&mut bytes).map_err(|e| OutputError::Encode {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(bytes.into_inner())
}

#[cfg(feature = "exr")]
fn check_size(width: u32, height: u32, n: usize, path: &Path) -> Result<(), OutputError> {
    if width == 0 || height == 0 || width as usize * height as usize != n {
        return Err(OutputError::Encode {
            path: path.to_path_buf(),
            message: format!("{width}x{height} image with {n} values"),
        });
    }
    Ok(())
}

/// Reads an EXR written by [`write_exr`] or [`write_grey_exr`] (or any EXR whose first layer
/// has R, G, B channels, or a single Y channel, any sample type) into a film. A grey map
/// becomes equal channels.
pub fn read_exr(path: &Path) -> Result<Film, OutputError> {
    let (w, h, px) = decode_exr_rgb(path).map_err(|e| match e {
        ExrReadError::Io(source) => OutputError::Io {
            path: path.to_path_buf(),
            action: "read",
            source,
        },
        ExrReadError::Decode(message) => OutputError::Decode {
            path: path.to_path_buf(),
            message,
        },
    })?;
    Ok(Film {
        width: w,
        height: h,
        pixels: px
            .into_iter()
            .map(|p| Rgb::new(p[0] as f64, p[1] as f64, p[2] as f64))
            .collect(),
    })
}

/// The metadata pairs (`name`, `value`) that [`write_exr_with_attributes`] recorded in the
/// header of the EXR at `path`, in their order; empty when it has none. Only the header is
/// read.
pub fn read_exr_metadata(path: &Path) -> Result<Vec<(String, String)>, OutputError> {
    #[cfg(feature = "exr")]
    {
        use exr::meta::attribute::{AttributeValue, Text};
        let bytes = fs::read(path).map_err(|source| OutputError::Io {
            path: path.to_path_buf(),
            action: "read",
            source,
        })?;
        let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
            .map_err(|e| OutputError::Decode {
                path: path.to_path_buf(),
                message: e.to_string(),
            })?;
        let text = meta.headers.first().and_then(|h| {
            match h.own_attributes.other.get(&Text::from(METADATA_ATTRIBUTE)) {
                Some(AttributeValue::Text(t)) => Some(t.to_string()),
                _ => None,
            }
        });
        Ok(text
            .iter()
            .flat_map(|t| t.split("; "))
            .filter_map(|pair| pair.split_once('='))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect())
    }
    #[cfg(not(feature = "exr"))]
    {
        Err(OutputError::Unsupported {
            path: path.to_path_buf(),
            feature: "exr",
        })
    }
}

/// Why an EXR could not be read.
#[derive(Debug)]
#[cfg_attr(not(feature = "exr"), allow(dead_code))]
pub(crate) enum ExrReadError {
    Io(std::io::Error),
    Decode(String),
}

/// The size (width, height) and channel count of the first layer of the EXR at `path`, from
/// its header alone.
pub(crate) fn exr_size(path: &Path) -> Result<(u32, u32, usize), ExrReadError> {
    #[cfg(feature = "exr")]
    {
        let file = fs::File::open(path).map_err(ExrReadError::Io)?;
        let meta = exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
            .map_err(|e| ExrReadError::Decode(e.to_string()))?;
        let header = meta
            .headers
            .first()
            .ok_or_else(|| ExrReadError::Decode("no layer".into()))?;
        let size = header.layer_size;
        let dim = |v: usize| {
            u32::try_from(v)
                .map_err(|_| ExrReadError::Decode(format!("image side {v} is too large")))
        };
        Ok((
            dim(size.width())?,
            dim(size.height())?,
            header.channels.list.len(),
        ))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = path;
        Err(ExrReadError::Decode(
            "EXR support needs the `exr` feature of het-bssrdf-tracer".into(),
        ))
    }
}

/// Reads the first valid layer of an EXR as RGB `f32` (row-major, row 0 at the top).
pub(crate) fn decode_exr_rgb(path: &Path) -> Result<(u32, u32, Vec<[f32; 3]>), ExrReadError> {
    #[cfg(feature = "exr")]
    {
        use exr::prelude::*;
        let bytes = fs::read(path).map_err(ExrReadError::Io)?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| ExrReadError::Decode(e.to_string()))?;
        let layer = &image.layer_data;
        let (w, h) = (layer.size.width(), layer.size.height());
        let find = |name: &str| {
            layer.channel_data.list.iter().find(|c| {
                let s = c.name.to_string();
                s == name || s.rsplit('.').next() == Some(name)
            })
        };
        let values =
            |c: &AnyChannel<FlatSamples>| -> Vec<f32> { c.sample_data.values_as_f32().collect() };
        let pixels: Vec<[f32; 3]> = match (find("R"), find("G"), find("B"), find("Y")) {
            (Some(r), Some(g), Some(b), _) => {
                let (r, g, b) = (values(r), values(g), values(b));
                (0..w * h).map(|i| [r[i], g[i], b[i]]).collect()
            }
            (_, _, _, Some(y)) => values(y).into_iter().map(|v| [v; 3]).collect(),
            _ => {
                return Err(ExrReadError::Decode(format!(
                    "no R, G, B or Y channels (found: {})",
                    layer
                        .channel_data
                        .list
                        .iter()
                        .map(|c| c.name.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        };
        if pixels.len() != w * h {
            return Err(ExrReadError::Decode(
                "channel sizes do not match the image size".into(),
            ));
        }
        Ok((w as u32, h as u32, pixels))
    }
    #[cfg(not(feature = "exr"))]
    {
        let _ = path;
        Err(ExrReadError::Decode(
            "EXR support needs the `exr` feature of het-bssrdf-tracer".into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unfinished_temporaries_are_removed_on_request_and_on_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        // A write in progress (staged, not committed) is registered for
        // remove_temporary_files (not called here: it is process-wide, and other tests write
        // files concurrently), and removed and unregistered when abandoned.
        let staged = Staged::write(&path, b"bytes").unwrap();
        let tmp = staged.tmp.clone();
        assert!(tmp.exists() && pending().contains(&tmp));
        drop(staged);
        assert!(!tmp.exists() && !pending().contains(&tmp));
        // A set whose last file cannot be written leaves nothing, temporaries included.
        let mut set = OutputSet::new();
        set.add(&dir.path().join("b.json"), b"{}".to_vec());
        set.add(&dir.path().join("missing/c.exr"), b"x".to_vec());
        assert!(set.commit().is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }

    #[test]
    fn srgb_round_trip_and_known_values() {
        // IEC 61966-2-1: 0.5 linear encodes to 0.7354; 0.0031308 is the knee.
        assert!((srgb_encode(0.5) - 0.735_356_983_052_449).abs() < 1e-9);
        assert!((srgb_encode(0.003_130_8) - 0.040_449_936).abs() < 1e-8);
        for i in 0..=100 {
            let x = i as f64 / 100.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-12);
        }
        assert_eq!(preview_byte(1.0, 0.0), 255);
        assert_eq!(preview_byte(0.25, 1.0), preview_byte(0.5, 0.0));
        assert_eq!(preview_byte(f64::NAN, 0.0), 0);
    }
}

//! The external files of a glTF file (buffer and image URIs), read as untrusted input: a glTF
//! file downloaded from the web may name any path.
//!
//! A URI is a `data:` URI (its bytes are in the document), or a file: a relative reference
//! (`%XX` escapes decoded), an absolute path, or a `file:` URI. A file must be a regular file
//! inside the model's folder (the directory of the `.gltf` or `.glb`, symbolic links
//! resolved) unless the user allows files outside it ([`AssetScope::Anywhere`]: the command
//! line's `--allow-outside-assets`, or a shape's `allow_outside_assets = true`). Whatever the
//! scope, a device, FIFO, socket or directory is refused before it is opened, so that
//! `/dev/zero` cannot fill memory and a FIFO cannot block the loader; files are opened without
//! blocking and read up to a bound. Errors name the URI and the model, never another file's
//! size or contents.

// Without the `gltf` feature only [`AssetScope`] is used (by the scene loader's options).
#![cfg_attr(not(feature = "gltf"), allow(dead_code))]

use std::io::Read;
use std::path::{Component, Path, PathBuf};

/// Where a glTF file's external files may be.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AssetScope {
    /// Inside the model's folder only (the default).
    #[default]
    ModelFolder,
    /// Anywhere the process can read (still regular files only).
    Anywhere,
}

/// What a URI names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Resolved {
    /// A `data:` URI.
    Data,
    /// A regular file, by its canonical path.
    File(PathBuf),
    /// A file that does not exist (an error when it is read).
    Missing,
}

/// The model's folder, canonical (symbolic links resolved).
#[derive(Debug, Clone)]
pub(crate) struct ModelFolder(PathBuf);

impl ModelFolder {
    /// The folder of the glTF file `model`.
    pub fn of(model: &Path) -> Result<Self, String> {
        let dir = match model.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        dir.canonicalize()
            .map(ModelFolder)
            .map_err(|e| format!("cannot resolve the model's folder: {e}"))
    }
}

/// Resolves `uri` (see the module docs) against the model's `folder` within `scope`, without
/// reading anything. `Err` holds the reason, to be prefixed with the URI's owner.
pub(crate) fn resolve(
    uri: &str,
    folder: &ModelFolder,
    scope: AssetScope,
) -> Result<Resolved, String> {
    if uri.starts_with("data:") {
        return Ok(Resolved::Data);
    }
    let decoded = if let Some(rest) = uri
        .strip_prefix("file://")
        .or_else(|| uri.strip_prefix("file:"))
    {
        percent_decode(rest)
    } else if uri.contains(':') {
        return Err(format!(
            "uri `{uri}`: only relative paths and data: URIs are read (a scheme such as http: \
             is not)"
        ));
    } else {
        percent_decode(uri)
    };
    let outside = || {
        format!(
            "uri `{uri}` names a file outside the model's folder `{}`; external files must be \
             inside it (allow others with --allow-outside-assets, or `allow_outside_assets = \
             true` on the shape)",
            folder.0.display()
        )
    };
    let candidate = normalize(&folder.0.join(&decoded));
    if scope == AssetScope::ModelFolder && !candidate.starts_with(&folder.0) {
        // Refused before the file system is asked anything about the path.
        return Err(outside());
    }
    let canonical = match candidate.canonicalize() {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Resolved::Missing),
        Err(e) => return Err(format!("uri `{uri}` cannot be resolved: {e}")),
    };
    if scope == AssetScope::ModelFolder && !canonical.starts_with(&folder.0) {
        // A symbolic link inside the folder to a file outside it.
        return Err(outside());
    }
    match std::fs::metadata(&canonical) {
        Ok(m) if m.is_file() => Ok(Resolved::File(canonical)),
        Ok(m) => Err(format!(
            "uri `{uri}` names a {}, not a regular file",
            crate::output::file_kind(&m.file_type())
        )),
        Err(e) => Err(format!("uri `{uri}` cannot be read: {e}")),
    }
}

/// `path` with `.` and `..` components resolved lexically (no file system access).
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// Reads the regular file `path` (from [`resolve`]), at most `limit` bytes: `Err` when it
/// holds more (`what` names the bound in the message) or is no longer a regular file. The file
/// is opened without blocking (a FIFO put in its place cannot hang the loader).
pub(crate) fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    use std::os::unix::fs::OpenOptionsExt;
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| format!("cannot open it: {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("cannot read it: {e}"))?;
    if !meta.is_file() {
        return Err(format!(
            "it is a {}, not a regular file",
            crate::output::file_kind(&meta.file_type())
        ));
    }
    let mut bytes = Vec::with_capacity(meta.len().min(limit) as usize);
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read it: {e}"))?;
    if bytes.len() as u64 > limit {
        return Err(format!("the file holds more bytes than {what}"));
    }
    Ok(bytes)
}

/// `%XX` escapes decoded (glTF URIs are RFC 3986 references).
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_stay_in_the_folder_unless_allowed() {
        let root = tempfile::tempdir().unwrap();
        let model = root.path().join("model");
        std::fs::create_dir_all(model.join("sub")).unwrap();
        std::fs::write(model.join("sub/a b.bin"), b"x").unwrap();
        std::fs::write(root.path().join("secret.bin"), b"s").unwrap();
        std::os::unix::fs::symlink(root.path().join("secret.bin"), model.join("link.bin")).unwrap();
        let folder = ModelFolder::of(&model.join("m.gltf")).unwrap();
        let inside = |uri: &str| resolve(uri, &folder, AssetScope::ModelFolder);
        let canonical = model.canonicalize().unwrap().join("sub/a b.bin");
        assert_eq!(
            inside("sub/a%20b.bin"),
            Ok(Resolved::File(canonical.clone()))
        );
        assert_eq!(
            inside("./sub/../sub/a%20b.bin"),
            Ok(Resolved::File(canonical))
        );
        assert_eq!(
            inside("data:application/octet-stream;base64,AAAA"),
            Ok(Resolved::Data)
        );
        assert_eq!(inside("missing.bin"), Ok(Resolved::Missing));
        let secret = root.path().join("secret.bin");
        for uri in [
            "../secret.bin".to_string(),
            "sub/../../secret.bin".to_string(),
            secret.display().to_string(),
            format!("file://{}", secret.display()),
            "link.bin".to_string(),
            "/etc/passwd".to_string(),
        ] {
            let e = inside(&uri).unwrap_err();
            assert!(e.contains("outside the model's folder"), "{uri}: {e}");
            assert!(
                matches!(
                    resolve(&uri, &folder, AssetScope::Anywhere),
                    Ok(Resolved::File(_))
                ),
                "{uri}"
            );
        }
        assert!(
            inside("http://example.invalid/a.bin")
                .unwrap_err()
                .contains("scheme")
        );
        let dev = resolve("/dev/zero", &folder, AssetScope::Anywhere).unwrap_err();
        assert!(dev.contains("character device"), "{dev}");
    }

    #[test]
    fn reads_are_bounded() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        std::fs::write(&p, [7u8; 10]).unwrap();
        assert_eq!(read_bounded(&p, 10, "10 bytes").unwrap(), vec![7u8; 10]);
        let e = read_bounded(&p, 9, "its byteLength").unwrap_err();
        assert_eq!(e, "the file holds more bytes than its byteLength");
        assert!(
            read_bounded(Path::new("/dev/zero"), 9, "x")
                .unwrap_err()
                .contains("character device")
        );
    }
}

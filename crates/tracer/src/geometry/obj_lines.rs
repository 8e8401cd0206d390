//! File lines for OBJ errors, and the guard that keeps an OBJ file's reading streamed.
//!
//! tobj re-indexes vertices (one index per vertex) and triangulates faces, so "vertex 27" or
//! "triangle 3" of the loaded mesh does not say where the problem is in the file. When loading
//! or validation fails, [`first_problem`] scans the file once, line by line, and names the
//! first line that causes it: a non-finite or unreadable `v`/`vn`/`vt` value, a face index out
//! of range (OBJ indices count from 1; negative ones count back from the latest vertex), or a
//! face with a zero-area triangle.
//!
//! OBJ is text read line by line, and a line is read whole: a 2 GB file of NUL bytes (no line
//! break) would be one 2 GB line. [`TextGuard`] fails the read at the first NUL byte or at a
//! line longer than [`MAX_LINE`], after one buffer of the file, and keeps the reason with its
//! line.

use std::io::{BufRead, Read};

use glam::DVec3;

/// The longest OBJ line read, in bytes (a face of a few hundred thousand corners).
pub(crate) const MAX_LINE: usize = 16 << 20;

/// A reader of an OBJ file's bytes that fails with [`std::io::ErrorKind::InvalidData`] at the
/// first NUL byte or at a line longer than [`MAX_LINE`]; [`TextGuard::problem`] then says
/// which line and why. Each byte is checked once, when it is first buffered.
pub(crate) struct TextGuard<R> {
    inner: R,
    /// Bytes at the front of `inner`'s buffer already checked.
    checked: usize,
    /// Line of the next byte to check, from 1.
    line: usize,
    /// Bytes of that line before it.
    line_len: usize,
    problem: Option<(usize, String)>,
}

impl<R: BufRead> TextGuard<R> {
    pub(crate) fn new(inner: R) -> Self {
        Self {
            inner,
            checked: 0,
            line: 1,
            line_len: 0,
            problem: None,
        }
    }

    /// Why the reading failed, with the line (from 1), if the guard failed it.
    pub(crate) fn problem(&self) -> Option<&(usize, String)> {
        self.problem.as_ref()
    }

    fn fail(&mut self, message: String) -> std::io::Error {
        self.problem = Some((self.line, message.clone()));
        std::io::Error::new(std::io::ErrorKind::InvalidData, message)
    }
}

impl<R: BufRead> BufRead for TextGuard<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if let Some((_, message)) = &self.problem {
            let message = message.clone();
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                message,
            ));
        }
        let buf = self.inner.fill_buf()?;
        let mut bad = None;
        for &b in &buf[self.checked.min(buf.len())..] {
            match b {
                0 => {
                    bad = Some("holds a NUL byte: this is not a text OBJ file".to_string());
                    break;
                }
                b'\n' => {
                    self.line += 1;
                    self.line_len = 0;
                }
                _ => {
                    self.line_len += 1;
                    if self.line_len > MAX_LINE {
                        bad = Some(format!(
                            "is longer than {} MiB: this is not a text OBJ file",
                            MAX_LINE >> 20
                        ));
                        break;
                    }
                }
            }
            self.checked += 1;
        }
        if let Some(message) = bad {
            return Err(self.fail(message));
        }
        self.inner.fill_buf()
    }

    fn consume(&mut self, amt: usize) {
        self.checked = self.checked.saturating_sub(amt);
        self.inner.consume(amt);
    }
}

impl<R: BufRead> Read for TextGuard<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let n = {
            let available = self.fill_buf()?;
            let n = available.len().min(out.len());
            out[..n].copy_from_slice(&available[..n]);
            n
        };
        self.consume(n);
        Ok(n)
    }
}

/// The first problem line of the OBJ text `reader` yields, as `(line number from 1,
/// message)`; read line by line through a [`TextGuard`].
pub(crate) fn first_problem(reader: impl BufRead) -> Option<(usize, String)> {
    let mut guard = TextGuard::new(reader);
    let mut positions: Vec<DVec3> = Vec::new();
    let (mut normals, mut uvs) = (0usize, 0usize);
    let mut raw = String::new();
    for line in 1.. {
        raw.clear();
        match guard.read_line(&mut raw) {
            Ok(0) => break,
            Ok(_) => {}
            Err(e) => {
                return Some(
                    guard
                        .problem()
                        .cloned()
                        .unwrap_or((line, format!("cannot be read: {e}"))),
                );
            }
        }
        let mut words = raw.split_whitespace();
        let Some(tag) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        match tag {
            "v" | "vn" | "vt" => {
                let need = if tag == "vt" { 1 } else { 3 };
                let values: Vec<f64> = match rest.iter().map(|w| w.parse::<f64>()).collect() {
                    Ok(v) => v,
                    Err(_) => return Some((line, format!("`{tag}` has an unreadable number"))),
                };
                if values.len() < need {
                    return Some((
                        line,
                        format!("`{tag}` needs {need} numbers, got {}", values.len()),
                    ));
                }
                if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                    return Some((line, format!("`{tag}` has a non-finite value {v}")));
                }
                match tag {
                    "v" => positions.push(DVec3::new(values[0], values[1], values[2])),
                    "vn" => normals += 1,
                    _ => uvs += 1,
                }
            }
            "f" => {
                let mut corners = Vec::with_capacity(rest.len());
                for word in &rest {
                    for (slot, (field, count)) in word
                        .split('/')
                        .zip([positions.len(), uvs, normals])
                        .enumerate()
                    {
                        if field.is_empty() {
                            continue;
                        }
                        let Ok(i) = field.parse::<i64>() else {
                            return Some((line, format!("face index `{field}` is not a number")));
                        };
                        let resolved = if i < 0 { count as i64 + i } else { i - 1 };
                        if i == 0 || resolved < 0 || resolved >= count as i64 {
                            let what = ["vertex", "texture coordinate", "normal"][slot];
                            return Some((
                                line,
                                format!(
                                    "face refers to {what} {i}, but only {count} are defined above it"
                                ),
                            ));
                        }
                        if slot == 0 {
                            corners.push(positions[resolved as usize]);
                        }
                    }
                }
                if corners.len() < 3 {
                    return Some((
                        line,
                        format!("a face needs 3 vertices, got {}", corners.len()),
                    ));
                }
                for i in 1..corners.len() - 1 {
                    let (a, b, c) = (corners[0], corners[i], corners[i + 1]);
                    if (b - a).cross(c - a) == DVec3::ZERO {
                        return Some((
                            line,
                            "face is degenerate: a triangle of it has zero area".into(),
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(text: &str) -> Option<(usize, String)> {
        first_problem(text.as_bytes())
    }

    #[test]
    fn finds_the_line() {
        let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(problem(ok), None);
        assert_eq!(problem("v 0 0 0\nv 1 nan 0\n").unwrap().0, 2);
        assert_eq!(problem(&format!("{ok}f 1 2 4\n")).unwrap().0, 5);
        assert_eq!(problem(&format!("{ok}f 1 2 -4\n")).unwrap().0, 5);
        assert_eq!(problem(&format!("{ok}f -1 -2 -3\n")), None);
        assert_eq!(problem(&format!("{ok}f 1 1 2\n")).unwrap().0, 5);
        assert_eq!(problem(&format!("{ok}v 0 0\0 0\n")).unwrap().0, 5);
    }

    /// The guard stops at the first NUL byte or overlong line, whatever the buffer size, and
    /// passes text through unchanged.
    #[test]
    fn the_guard_stops_binary_input_early() {
        let text = "v 0 0 0\nv 1 0 0\n".repeat(1000);
        for cap in [1, 7, 64, 8192] {
            let mut g = TextGuard::new(std::io::BufReader::with_capacity(cap, text.as_bytes()));
            let mut out = String::new();
            g.read_to_string(&mut out).unwrap();
            assert_eq!(out, text);
            let bad = format!("{text}v 1\0");
            let mut g = TextGuard::new(std::io::BufReader::with_capacity(cap, bad.as_bytes()));
            assert!(g.read_to_string(&mut String::new()).is_err());
            assert_eq!(g.problem().unwrap().0, 2001, "capacity {cap}");
        }
        // An endless stream of NUL bytes is refused after one buffer.
        let mut g = TextGuard::new(std::io::BufReader::new(std::io::repeat(0)));
        let e = g.read_line(&mut String::new()).unwrap_err();
        assert!(e.to_string().contains("NUL"), "{e}");
        let long = std::io::repeat(b'v').take(MAX_LINE as u64 + 10);
        let mut g = TextGuard::new(std::io::BufReader::new(long));
        assert!(g.read_line(&mut String::new()).is_err());
        assert!(g.problem().unwrap().1.contains("longer than"));
    }
}

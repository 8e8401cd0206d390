//! Key paths and lines in a TOML document: which key an error position belongs to, and on
//! which line a key path is written.
//!
//! toml's spans of `[[array]]` elements cover only their header, so "the innermost value
//! containing the position" does not work; instead every key (and array element) is listed
//! with the position where it starts, and a position belongs to the last key starting at or
//! before it.

use std::collections::HashMap;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// Every key path of a document with its start offset, plus the text for line numbers.
///
/// [`Locator::line_of_key`] is a hash lookup (a scene of N shapes asks it for each shape: a
/// scan of the key list made loading quadratic, 100,000 boxes taking over 20 minutes);
/// [`Locator::key_at`] scans the list, but only errors ask it.
#[derive(Debug, Default)]
pub(crate) struct Locator {
    /// `(start offset, key path)`, in document order of traversal.
    keys: Vec<(usize, String)>,
    /// Key path → start offset of its first occurrence in `keys`.
    by_path: HashMap<String, usize>,
    /// Offsets of line starts.
    line_starts: Vec<usize>,
}

impl Locator {
    pub fn new(text: &str, root: &Spanned<DeTable<'_>>) -> Self {
        let mut keys = Vec::new();
        collect_table(root.get_ref(), "", &mut keys);
        let mut by_path = HashMap::with_capacity(keys.len());
        for (pos, path) in &keys {
            by_path.entry(path.clone()).or_insert(*pos);
        }
        let mut line_starts = vec![0];
        line_starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        Self {
            keys,
            by_path,
            line_starts,
        }
    }

    /// A locator with no document (builder scenes).
    pub fn empty() -> Self {
        Self::default()
    }

    /// 1-based line of byte offset `pos`.
    pub fn line_of(&self, pos: usize) -> Option<usize> {
        if self.line_starts.is_empty() {
            return None;
        }
        Some(self.line_starts.partition_point(|&s| s <= pos))
    }

    /// The key path a byte offset belongs to (empty when before every key).
    pub fn key_at(&self, pos: usize) -> String {
        let mut best: Option<&(usize, String)> = None;
        for k in &self.keys {
            if k.0 <= pos {
                match best {
                    Some(b) if b.0 > k.0 || (b.0 == k.0 && b.1.len() >= k.1.len()) => {}
                    _ => best = Some(k),
                }
            }
        }
        best.map(|b| b.1.clone()).unwrap_or_default()
    }

    /// The line where `key` (a path like `material[1].g`) is written; for a key that is not in
    /// the file (a missing key, a default), the line of its closest written ancestor.
    pub fn line_of_key(&self, key: &str) -> Option<usize> {
        let mut k = key;
        loop {
            if let Some(pos) = self.by_path.get(k) {
                return self.line_of(*pos);
            }
            // Strip the last segment: `.name` or `[i]`.
            let cut = k.rfind(['.', '[']).filter(|&i| i > 0)?;
            k = &k[..cut];
        }
    }
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

fn collect_table(t: &DeTable<'_>, prefix: &str, out: &mut Vec<(usize, String)>) {
    for (k, v) in t.iter() {
        let path = join(prefix, k.get_ref());
        out.push((k.span().start, path.clone()));
        collect_value(v, &path, out);
    }
}

fn collect_value(v: &Spanned<DeValue<'_>>, path: &str, out: &mut Vec<(usize, String)>) {
    match v.get_ref() {
        DeValue::Table(t) => collect_table(t, path, out),
        DeValue::Array(a) => {
            for (i, e) in a.iter().enumerate() {
                let p = format!("{path}[{i}]");
                out.push((e.span().start, p.clone()));
                collect_value(e, &p, out);
            }
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_and_lines() {
        let text = "[render]\nwidth = 3\n\n[[shape]]\ntype = \"box\"\n\n[[shape]]\ntype = \"sphere\"\nradius = \"a\"\nv = { w = [1, 2] }\n";
        let root = DeTable::parse(text).unwrap();
        let loc = Locator::new(text, &root);
        let pos = text.find("\"a\"").unwrap();
        assert_eq!(loc.key_at(pos), "shape[1].radius");
        assert_eq!(loc.line_of(pos), Some(9));
        let pos = text.find("2]").unwrap();
        assert_eq!(loc.key_at(pos), "shape[1].v.w[1]");
        assert_eq!(loc.line_of_key("shape[1].radius"), Some(9));
        assert_eq!(loc.line_of_key("shape[1].missing"), Some(7));
        assert_eq!(loc.line_of_key("render.width"), Some(2));
    }
}

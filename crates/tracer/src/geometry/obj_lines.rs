//! File lines for OBJ errors. tobj re-indexes vertices (one index per vertex) and triangulates
//! faces, so "vertex 27" or "triangle 3" of the loaded mesh does not say where the problem is
//! in the file. When loading or validation fails, this scans the file once and names the first
//! line that causes it: a non-finite or unreadable `v`/`vn`/`vt` value, a face index out of
//! range (OBJ indices count from 1; negative ones count back from the latest vertex), or a
//! face with a zero-area triangle.

use glam::DVec3;

/// The first problem line of `text` as `(line number from 1, message)`.
pub(crate) fn first_problem(text: &str) -> Option<(usize, String)> {
    let mut positions: Vec<DVec3> = Vec::new();
    let (mut normals, mut uvs) = (0usize, 0usize);
    for (k, raw) in text.lines().enumerate() {
        let line = k + 1;
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

    #[test]
    fn finds_the_line() {
        let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(first_problem(ok), None);
        assert_eq!(first_problem("v 0 0 0\nv 1 nan 0\n").unwrap().0, 2);
        assert_eq!(first_problem(&format!("{ok}f 1 2 4\n")).unwrap().0, 5);
        assert_eq!(first_problem(&format!("{ok}f 1 2 -4\n")).unwrap().0, 5);
        assert_eq!(first_problem(&format!("{ok}f -1 -2 -3\n")), None);
        assert_eq!(first_problem(&format!("{ok}f 1 1 2\n")).unwrap().0, 5);
    }
}

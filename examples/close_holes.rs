//! Closes the holes of a scanned mesh and writes it as an OBJ that bounds a volume, so that the
//! path tracer (and `--method auto`) can render it as a translucent object:
//!
//!     cargo run --release --example close_holes -- IN.ply|IN.obj OUT.obj
//!
//! Each hole (a loop of edges used by one triangle) is closed by a fan around its mean
//! (`tracer::geometry::holes::fill_holes`). Vertices are written in `f64` precision, with
//! area-weighted vertex normals when the input has none (smooth shading). The output is written
//! to a temporary file and renamed into place. `scripts/fetch-bunny.sh` runs this on the
//! Stanford bunny.

use std::io::Write;
use std::path::Path;

use het_bssrdf::het_estimate::glam::{DVec3, Vec3};
use het_bssrdf::tracer::geometry::TriangleMesh;
use het_bssrdf::tracer::geometry::holes::fill_holes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, output] = args.as_slice() else {
        return Err("usage: close_holes IN.ply|IN.obj OUT.obj".into());
    };
    let input = Path::new(input);
    let mut mesh = match input.extension().and_then(|e| e.to_str()) {
        Some("ply") => het_bssrdf::tracer::geometry::ply::load_ply(input)?,
        Some("obj") => het_bssrdf::tracer::geometry::obj::load_obj(input)?,
        _ => return Err(format!("{}: expected a .ply or .obj file", input.display()).into()),
    };
    mesh.validate(&input.display().to_string())?;
    let before = mesh.topology();
    let holes = fill_holes(&mut mesh);
    let after = mesh.topology();
    println!(
        "{}: {} before; {holes} holes closed; {}",
        input.display(),
        before.summary(),
        after.summary()
    );
    if !after.is_closed() {
        return Err(format!(
            "{}: still not closed after filling its holes ({}): the mesh has non-manifold or \
             inconsistently oriented edges, which filling cannot repair",
            input.display(),
            after.summary()
        )
        .into());
    }
    if mesh.normals.is_none() {
        mesh.normals = Some(vertex_normals(&mesh));
    }
    write_obj(&mesh, Path::new(output))?;
    println!("wrote {output}");
    Ok(())
}

/// Area-weighted vertex normals (the sum of the adjacent triangles' cross products).
fn vertex_normals(mesh: &TriangleMesh) -> Vec<Vec3> {
    let mut n = vec![DVec3::ZERO; mesh.positions.len()];
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|k| mesh.positions[k as usize]);
        let face = (b - a).cross(c - a);
        for &k in t {
            n[k as usize] += face;
        }
    }
    n.into_iter()
        .map(|v| v.normalize_or_zero().as_vec3())
        .collect()
}

/// Writes `mesh` as OBJ (`v`, `vn`, `f v//vn`) through a temporary file renamed into place.
fn write_obj(mesh: &TriangleMesh, path: &Path) -> std::io::Result<()> {
    let tmp = path.with_extension("obj.tmp");
    {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        writeln!(w, "# written by `cargo run --example close_holes`")?;
        for p in &mesh.positions {
            writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
        }
        let normals = mesh.normals.as_deref().unwrap_or_default();
        for n in normals {
            writeln!(w, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|k| k + 1);
            if normals.is_empty() {
                writeln!(w, "f {a} {b} {c}")?;
            } else {
                writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
            }
        }
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
    }
    std::fs::rename(&tmp, path)
}

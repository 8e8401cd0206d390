//! How the cost of a scene grows with its number of objects: loading, and rays per second.
//!
//!     cargo run --release --example object_scaling -- [load N…] [rays N…]
//!
//! `load N…` (default 5000 10000 20000 100000) writes a scene file of N diffuse boxes in a
//! grid to a temporary directory and times `Scene::load` on it: wall time, and CPU time of the
//! whole process (user + system, from `/proc/self/stat`) spent in the load. Loading should be
//! linear in N (target: 100,000 boxes in under 10 s of CPU).
//!
//! `rays N…` (default 10 100 1000 3000) builds N boxes of a 20 × 20 grid (each a quarter of
//! its cell) and traces, on one thread, rays from above aimed at a random point of a random
//! box's top, so that every ray hits and only the number of objects differs (the `objects`
//! benchmark's `closest-on-box` set). Besides the rate it prints, per ray, how many objects'
//! boxes the ray enters before its hit (those whose own tree is traversed), the depth of the
//! top-level tree (8-wide: ⌈log₈ N⌉), and the rate of the same rays all aimed at one box (the
//! same top-level path and object every time, so that their data stay in cache): together
//! they split the remaining cost of many objects between per-ray work, tree depth and memory
//! traffic (docs/scaling.md).

use std::time::Instant;

use bssrdf_core::glam::DVec3;
use het_bssrdf::tracer::geometry::{Geometry, Ray, primitives};
use het_bssrdf::tracer::rng::Rng;
use het_bssrdf::tracer::scene::Scene;

/// CPU seconds (user + system) this process has used, from `/proc/self/stat` (clock ticks of
/// 1/100 s, Linux's USER_HZ); 0 where the file does not exist.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // The fields after the command name (which is in parentheses and may hold spaces).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let fields: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// A scene file of `n` diffuse boxes in a square grid, seen from above.
fn boxes_scene(n: usize) -> String {
    let k = (n as f64).sqrt().ceil() as usize;
    let mut s = String::from(
        "[render]\nwidth = 64\nheight = 64\nspp = 1\n\n\
         [camera]\ntype = \"orthographic\"\ncentre = [0.0, 0.0, 10.0]\n\
         direction = [0.0, 0.0, -1.0]\nup = [0.0, 1.0, 0.0]\nwidth = 20.0\nheight = 20.0\n\n\
         [[material]]\nname = \"grey\"\ntype = \"diffuse\"\nalbedo = 0.5\n\n\
         [[light]]\ntype = \"directional\"\ndirection = [0.0, 0.0, -1.0]\nirradiance = 1.0\n",
    );
    let cell = 20.0 / k as f64;
    for i in 0..n {
        let (x, y) = ((i % k) as f64, (i / k) as f64);
        let (x0, y0) = (-10.0 + x * cell, -10.0 + y * cell);
        s.push_str(&format!(
            "\n[[shape]]\ntype = \"box\"\nmaterial = \"grey\"\nmin = [{x0}, {y0}, -0.5]\n\
             max = [{}, {}, 0.5]\n",
            x0 + 0.5 * cell,
            y0 + 0.5 * cell
        ));
    }
    s
}

fn load(counts: &[usize]) -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::temp_dir().join(format!("object-scaling-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    println!("objects  load wall (s)  load CPU (s)  CPU per object (µs)");
    for &n in counts {
        let path = dir.join(format!("boxes-{n}.toml"));
        std::fs::write(&path, boxes_scene(n))?;
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let scene = Scene::load(&path)?;
        let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_seconds() - c0);
        assert_eq!(scene.objects().len(), n);
        println!(
            "{n:>7}  {wall:>13.2}  {cpu:>12.2}  {:>19.1}",
            cpu / n as f64 * 1e6
        );
        std::fs::remove_file(&path)?;
    }
    std::fs::remove_dir(&dir)?;
    Ok(())
}

fn dir(rng: &mut Rng) -> DVec3 {
    let z = 1.0 - 2.0 * rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * rng.uniform();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Entry distance of the ray into `[lo, hi]`, if it enters before `t_max`.
fn enters(lo: DVec3, hi: DVec3, r: &Ray, t_max: f64) -> bool {
    let inv = DVec3::ONE / r.dir;
    let (t0, t1) = ((lo - r.origin) * inv, (hi - r.origin) * inv);
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

fn rays(counts: &[usize]) {
    const RAYS: usize = 200_000;
    println!(
        "objects  Mrays/s (1 thread)  boxes entered per ray  top-level depth ⌈log₈ N⌉  \
         Mrays/s, all at one box"
    );
    let mut rng = Rng::from_keys(99, &[]);
    let mut base = None;
    for &n in counts {
        let k = (n as f64).sqrt().ceil() as usize;
        let cell = 20.0 / k as f64;
        let meshes = (0..n)
            .map(|i| {
                let (x, y) = ((i % k) as f64, (i / k) as f64);
                let lo = DVec3::new(-10.0 + x * cell, -10.0 + y * cell, -0.5);
                primitives::cuboid(lo, lo + DVec3::new(0.5 * cell, 0.5 * cell, 1.0))
            })
            .collect();
        let g = Geometry::build(meshes);
        let aim = |rng: &mut Rng, one_box: bool| -> Vec<Ray> {
            (0..RAYS)
                .map(|_| {
                    let i = if one_box {
                        n / 2
                    } else {
                        ((rng.uniform() * n as f64) as usize).min(n - 1)
                    };
                    let (x, y) = ((i % k) as f64, (i / k) as f64);
                    let target = DVec3::new(
                        -10.0 + (x + 0.5 * rng.uniform()) * cell,
                        -10.0 + (y + 0.5 * rng.uniform()) * cell,
                        0.5,
                    );
                    let o = DVec3::new(0.0, 0.0, 30.0) + 5.0 * dir(rng);
                    Ray::new(o, (target - o).normalize())
                })
                .collect()
        };
        let set = aim(&mut rng, false);
        let one = aim(&mut rng, true);
        // Warm up, then time the best of three passes.
        let rate_of = |set: &[Ray]| {
            let hits = set.iter().filter(|r| g.intersect(r).is_some()).count();
            let mut best = f64::INFINITY;
            for _ in 0..3 {
                let t0 = Instant::now();
                let h = set
                    .iter()
                    .filter(|r| std::hint::black_box(g.intersect(r)).is_some())
                    .count();
                best = best.min(t0.elapsed().as_secs_f64());
                assert_eq!(h, hits);
            }
            RAYS as f64 / best / 1e6
        };
        let rate = rate_of(&set);
        let rate_one = rate_of(&one);
        let entered: usize = set
            .iter()
            .map(|r| {
                let t_hit = g.intersect(r).map_or(f64::INFINITY, |h| h.t);
                (0..n as u32)
                    .filter(|&o| {
                        let (lo, hi) = g.object_bounds(o);
                        enters(lo, hi, r, t_hit)
                    })
                    .count()
            })
            .sum();
        let depth = (n as f64).log(8.0).ceil().max(1.0);
        let base_rate = *base.get_or_insert(rate);
        println!(
            "{n:>7}  {rate:>18.2}  {:>21.2}  {depth:>25}  {rate_one:>21.2}   ({:.2}x the \
             first's time)",
            entered as f64 / RAYS as f64,
            base_rate / rate
        );
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let list = |key: &str, default: &[usize]| -> Result<Option<Vec<usize>>, String> {
        let Some(i) = args.iter().position(|a| a == key) else {
            return Ok(None);
        };
        let v: Vec<usize> = args[i + 1..]
            .iter()
            .take_while(|a| a.parse::<usize>().is_ok())
            .map(|a| a.parse().unwrap())
            .collect();
        Ok(Some(if v.is_empty() { default.to_vec() } else { v }))
    };
    let load_counts = list("load", &[5000, 10000, 20000, 100000])?;
    let ray_counts = list("rays", &[10, 100, 1000, 3000])?;
    if load_counts.is_none() && ray_counts.is_none() {
        load(&[5000, 10000, 20000, 100000])?;
        rays(&[10, 100, 1000, 3000]);
        return Ok(());
    }
    if let Some(c) = load_counts {
        load(&c)?;
    }
    if let Some(c) = ray_counts {
        rays(&c);
    }
    Ok(())
}

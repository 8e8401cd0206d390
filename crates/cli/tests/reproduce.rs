//! `het-bssrdf reproduce --scale tiny` through the built binary: every file the report refers
//! to exists, every number in the tables parses and is finite, the report agrees with
//! `errors.csv`, the headline claims (README, docs/results.md) hold at this scale (fixed seed), and an unusable
//! `--out` fails cleanly.

mod common;

use std::collections::HashMap;
use std::path::Path;

use common::{Scratch, listing};

/// A CSV file as a header and rows of named fields.
struct Csv {
    header: Vec<String>,
    rows: Vec<HashMap<String, String>>,
}

fn read_csv(path: &Path) -> Csv {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or_else(|| panic!("{} is empty", path.display()))
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            assert_eq!(cells.len(), header.len(), "{}: `{l}`", path.display());
            header
                .iter()
                .cloned()
                .zip(cells.into_iter().map(str::to_string))
                .collect()
        })
        .collect::<Vec<_>>();
    assert!(!rows.is_empty(), "{} has no rows", path.display());
    Csv { header, rows }
}

/// The field `name` of `row`, parsed; it must be finite.
#[track_caller]
fn finite(row: &HashMap<String, String>, name: &str, file: &str) -> f64 {
    let s = &row[name];
    let v: f64 = s
        .parse()
        .unwrap_or_else(|_| panic!("{file}: {name} = `{s}` is not a number ({row:?})"));
    assert!(v.is_finite(), "{file}: {name} = {v} ({row:?})");
    v
}

#[track_caller]
fn assert_file(root: &Path, rel: &str) {
    let p = root.join(rel);
    let len = std::fs::metadata(&p)
        .unwrap_or_else(|e| panic!("{rel} missing: {e}"))
        .len();
    assert!(len > 0, "{rel} is empty");
}

#[test]
fn tiny_scale_writes_a_complete_report() {
    let s = Scratch::new();
    let r = s.run(&["reproduce", "--scale", "tiny", "--out", "r"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let root = s.join("r");

    for rel in [
        "report.md",
        "errors.csv",
        "beam/stripe/pt.exr",
        "beam/stripe/pt.png",
        "beam/check/pt.exr",
        "slab/reference-pt.exr",
        "slab/pt.exr",
    ] {
        assert_file(&root, rel);
    }
    for study in ["converge-slab", "converge-beam-stripe"] {
        for f in [
            "convergence.csv",
            "convergence.png",
            "convergence.svg",
            "summary.json",
        ] {
            assert_file(&root, &format!("{study}/{f}"));
        }
    }
    let files = listing(&root);
    assert!(
        !files
            .iter()
            .any(|f| f.ends_with(".tmp") || f.contains("probe")),
        "temporary files left: {files:?}"
    );

    // errors.csv: every metric finite; an image for each method.
    let errors = read_csv(&root.join("errors.csv"));
    assert_eq!(
        errors.header,
        [
            "experiment",
            "method",
            "seconds",
            "rel_l2",
            "rmse",
            "mean_abs_log10"
        ]
    );
    let report = std::fs::read_to_string(root.join("report.md")).unwrap();
    assert!(
        report.contains("| experiment | method | seconds | rel. L2 | RMSE | mean abs log10 |"),
        "no error table header in report.md"
    );
    let mut experiments = std::collections::BTreeSet::new();
    for row in &errors.rows {
        let seconds = finite(row, "seconds", "errors.csv");
        assert!(seconds >= 0.0, "{row:?}");
        // mean |log10(T/R)| is over pixel pairs that are both positive; at the tiny scale every
        // map and render has such pixels, so it is finite too.
        for m in ["rel_l2", "rmse", "mean_abs_log10"] {
            let v = finite(row, m, "errors.csv");
            assert!(v >= 0.0, "{m} < 0: {row:?}");
        }
        let (exp, method) = (&row["experiment"], &row["method"]);
        experiments.insert(exp.clone());
        let image = match exp.as_str() {
            "checker slab" => format!("slab/{method}.exr"),
            e => {
                let preset = e.strip_prefix("beam ").expect("beam or checker slab");
                format!("beam/{preset}/{method}.exr")
            }
        };
        assert_file(&root, &image);
        // The report's row for it, with the same relative L2 to its 4 decimals.
        let prefix = format!("| {exp} | {method} |");
        let line = report
            .lines()
            .find(|l| l.starts_with(&prefix))
            .unwrap_or_else(|| panic!("report.md has no row `{prefix}`"));
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        let shown: f64 = cells[4].parse().expect("rel. L2 cell");
        let csv = finite(row, "rel_l2", "errors.csv");
        assert!(
            (shown - csv).abs() <= 0.5e-4 * (1.0 + csv.abs()),
            "{line} vs {csv}"
        );
    }
    let want: std::collections::BTreeSet<String> = ["beam stripe", "beam check", "checker slab"]
        .map(String::from)
        .into();
    assert_eq!(experiments, want);

    // Every image the report shows exists.
    for part in report.split("](").skip(1) {
        let rel = &part[..part.find(')').expect("closing parenthesis")];
        assert_file(&root, rel);
    }

    // The convergence studies.
    for study in ["converge-slab", "converge-beam-stripe"] {
        let file = format!("{study}/convergence.csv");
        let csv = read_csv(&root.join(&file));
        for h in ["method", "seconds", "rel_l2", "rmse", "mean_abs_log10"] {
            assert!(csv.header.iter().any(|x| x == h), "{file}: no `{h}` column");
        }
        for row in &csv.rows {
            for m in ["seconds", "rel_l2", "rmse", "mean_abs_log10"] {
                let v = finite(row, m, &file);
                assert!(v >= 0.0, "{file}: {m} < 0: {row:?}");
            }
        }
        assert!(
            csv.rows.iter().any(|r| r["method"] == "pt"),
            "{file}: no path-tracing runs"
        );
        let text = std::fs::read_to_string(root.join(study).join("summary.json")).unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).expect("summary.json parses");
        let methods = json["methods"].as_array().expect("methods array");
        assert!(!methods.is_empty(), "{study}: no methods");
        for m in methods {
            let name = m["method"].as_str().expect("method name");
            for k in ["converged_error", "speedup"] {
                let v = m[k]
                    .as_f64()
                    .unwrap_or_else(|| panic!("{study}: {name}.{k} = {}", m[k]));
                assert!(v.is_finite() && v > 0.0, "{study}: {name}.{k} = {v}");
            }
            // The summary's method is a BSSRDF method of the CSV, with a line in the report.
            assert!(csv.rows.iter().any(|r| r["method"] == name), "{name}");
            assert!(
                report
                    .lines()
                    .any(|l| l.starts_with(&format!("| {name} |"))),
                "report.md has no summary row for {name}"
            );
        }
    }

    // Headline claims, at the tiny scale and the default seed. (1) Sone beats Jensen's point
    // lookup on the check preset, for both profiles, in mean |log10(T/R)|: at this scale by a
    // factor ≈ 2.3 (0.29 against 0.67), so the margin asked for (1.5) is not noise.
    let metric = |exp: &str, method: &str| {
        let row = errors
            .rows
            .iter()
            .find(|r| r["experiment"] == exp && r["method"] == method)
            .unwrap_or_else(|| panic!("errors.csv has no row {exp} / {method}"));
        finite(row, "mean_abs_log10", "errors.csv")
    };
    for profile in ["dipole", "pbd"] {
        let sone = metric("beam check", &format!("sone-{profile}"));
        let jensen = metric("beam check", &format!("jensen-out-{profile}"));
        assert!(
            1.5 * sone < jensen,
            "check, {profile}: sone {sone} does not beat jensen-out {jensen}"
        );
    }
    // (2) The path tracer matches its reference (another seed, more samples): the image means
    // agree within 4 standard errors of the mean per-pixel difference (pixels independent).
    let pt = tracer::output::read_exr(&root.join("slab/pt.exr")).unwrap();
    let reference = tracer::output::read_exr(&root.join("slab/reference-pt.exr")).unwrap();
    assert_eq!(pt.pixels.len(), reference.pixels.len());
    let diffs: Vec<f64> = pt
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(a, b)| a[0] - b[0])
        .collect();
    let n = diffs.len() as f64;
    let mean = diffs.iter().sum::<f64>() / n;
    let var = diffs.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let se = (var / n).sqrt();
    let level = reference.pixels.iter().map(|p| p[0]).sum::<f64>() / n;
    assert!(
        mean.abs() < 4.0 * se,
        "path tracer {} against its reference {level}: difference {mean} ± {se}",
        mean + level
    );
    assert!(se < 0.04 * level, "too noisy to tell: se {se} at {level}");

    // The beam reference map: the right size and every value finite and non-negative.
    let map = tracer::output::read_exr(&root.join("beam/stripe/pt.exr")).unwrap();
    assert!(map.width > 0 && map.width == map.height);
    assert!(
        map.pixels
            .iter()
            .all(|p| p.0.iter().all(|v| v.is_finite() && *v >= 0.0))
    );
}

#[test]
fn existing_file_as_out_fails_cleanly() {
    let s = Scratch::new();
    s.write("r", "not a directory\n");
    s.assert_rejected(
        &["reproduce", "--scale", "tiny", "--out", "r"],
        1,
        &["--out", "`r`"],
    );
    s.assert_rejected(
        &["reproduce", "--scale", "tiny", "--out", "r/sub"],
        1,
        &["--out", "`r/sub`"],
    );
}

/// `--resume` reruns only the steps whose results are missing, leaves the finished ones'
/// files alone, and gives the same numbers as the uninterrupted run; a ledger of another seed
/// is refused, naming the file and the seed to use.
#[test]
fn resume_reruns_only_what_is_missing() {
    let s = Scratch::new();
    let r = s.run(&["reproduce", "--scale", "tiny", "--out", "r"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let root = s.join("r");
    let first = read_csv(&root.join("errors.csv"));
    let removed = ["slab/sone.exr", "beam/check/segment-pbd.exr"];
    for rel in removed {
        std::fs::remove_file(root.join(rel)).unwrap();
    }
    let kept = [
        "beam/stripe/pt.exr",
        "beam/check/sone-dipole.exr",
        "slab/reference-pt.exr",
        "slab/jensen-out.exr",
        "converge-slab/convergence.csv",
    ];
    let mtime = |rel: &str| {
        std::fs::metadata(root.join(rel))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before: Vec<_> = kept.iter().map(|rel| mtime(rel)).collect();

    let r = s.run(&["reproduce", "--scale", "tiny", "--out", "r", "--resume"]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    for rel in removed {
        assert_file(&root, rel);
    }
    for (rel, t) in kept.iter().zip(&before) {
        assert_eq!(mtime(rel), *t, "{rel} was rewritten");
    }
    let report = std::fs::read_to_string(root.join("report.md")).unwrap();
    assert!(report.contains("resumed: "), "no resume note in report.md");
    let second = read_csv(&root.join("errors.csv"));
    assert_eq!(first.rows.len(), second.rows.len());
    for (a, b) in first.rows.iter().zip(&second.rows) {
        assert_eq!(
            (&a["experiment"], &a["method"]),
            (&b["experiment"], &b["method"])
        );
        for m in ["rel_l2", "rmse", "mean_abs_log10"] {
            assert_eq!(a[m], b[m], "{m} of {} {}", a["experiment"], a["method"]);
        }
    }

    let r = s.run(&[
        "reproduce",
        "--scale",
        "tiny",
        "--out",
        "r",
        "--resume",
        "--seed",
        "2",
    ]);
    assert_ne!(r.code, Some(0));
    assert!(
        r.stderr.contains("reproduce-state.json") && r.stderr.contains("--seed 1"),
        "{}",
        r.stderr
    );
}

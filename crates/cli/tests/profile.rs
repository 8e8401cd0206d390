//! Integration tests of `het-bssrdf profile` through the built binary.

use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_het-bssrdf"))
        .arg("profile")
        .args(args)
        .output()
        .expect("run het-bssrdf")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}
fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn dipole_total_is_the_closed_form() {
    let o = run(&[
        "--model",
        "dipole",
        "--sigma-a",
        "0.01",
        "--sigma-s",
        "1",
        "--total",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let got: f64 = stdout(&o).trim().parse().expect("one number");
    // JMLH01 / Jensen & Buhler 2002 closed form, η = 1 (A = 1), computed here.
    let alpha: f64 = 1.0 / 1.01;
    let s = (3.0 * (1.0 - alpha)).sqrt();
    let want = 0.5 * alpha * (-s).exp() * (1.0 + (-(4.0 / 3.0) * s).exp());
    assert!((got - want).abs() < 1e-12 * want, "{got} vs {want}");
    // docs/physics.md#dipole: 0.7538…-ish regime; sanity against the tabulated neighbour α' = 0.99.
    assert!(got > 0.746714 && got < 0.912451);
}

#[test]
fn csv_has_header_and_requested_grid() {
    let o = run(&[
        "--model",
        "pbd",
        "--sigma-a",
        "0.01",
        "--sigma-s",
        "1",
        "--steps",
        "11",
        "--r-max",
        "5",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "r,value");
    assert_eq!(lines.len(), 12);
    let rs: Vec<f64> = lines[1..]
        .iter()
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(rs[0], 0.0);
    assert!((rs[10] - 5.0).abs() < 1e-12 && (rs[2] - 1.0).abs() < 1e-12);
    // docs/physics.md#beam-diffusion [computed]: PBD-MS at r = 1 (σs = 1, σa = 0.01, η = 1) is 3.252422e-2.
    let v: f64 = lines[3].split(',').nth(1).unwrap().parse().unwrap();
    assert!((v - 3.252422e-2).abs() < 1e-5 * 3.252422e-2, "{v}");
    // Defaults: 151 rows from 0 to 15.
    let o = run(&[
        "--model",
        "better-dipole",
        "--sigma-a",
        "0.1",
        "--sigma-s",
        "1",
    ]);
    assert_eq!(stdout(&o).lines().count(), 152);
}

#[test]
fn extreme_parameters_never_print_nan_or_inf() {
    let sigmas = [
        ("0", "1"),
        ("1", "0"),
        ("0", "0"),
        ("1e-6", "1e-6"),
        ("1e6", "1e6"),
        ("0", "1e6"),
        ("1e-9", "1"),
    ];
    for model in ["dipole", "pbd", "better-dipole"] {
        for (i, (sa, ss)) in sigmas.iter().enumerate() {
            let (g, eta) = [("0", "1"), ("0.99", "3"), ("-0.99", "1.5")][i % 3];
            for ss_flag in ["exclude", "include"] {
                let mut args = vec![
                    "--model",
                    model,
                    "--sigma-a",
                    sa,
                    "--sigma-s",
                    ss,
                    "--g",
                    g,
                    "--eta",
                    eta,
                    "--single-scattering",
                    ss_flag,
                    "--steps",
                    "7",
                    "--r-max",
                    "1e9",
                ];
                let o = run(&args);
                assert!(o.status.success(), "{args:?}: {}", stderr(&o));
                let t = stdout(&o).to_lowercase();
                assert!(!t.contains("nan") && !t.contains("inf"), "{args:?}: {t}");
                args.push("--total");
                let o = run(&args);
                let t = stdout(&o);
                let v: f64 = t.trim().parse().unwrap();
                assert!(v.is_finite() && v >= 0.0, "{args:?}: {t}");
            }
        }
    }
}

#[test]
fn invalid_input_fails_with_a_message_naming_the_parameter() {
    let cases: [(&[&str], &str); 8] = [
        (&["--sigma-a", "-1", "--sigma-s", "1"], "--sigma-a"),
        (&["--sigma-a", "0.1", "--sigma-s", "NaN"], "--sigma-s"),
        (&["--sigma-a", "0.1", "--sigma-s", "1", "--g", "1"], "--g"),
        (
            &["--sigma-a", "0.1", "--sigma-s", "1", "--g", "-1.5"],
            "--g",
        ),
        (
            &["--sigma-a", "0.1", "--sigma-s", "1", "--eta", "0.9"],
            "--eta",
        ),
        (
            &["--sigma-a", "0.1", "--sigma-s", "1", "--eta", "inf"],
            "--eta",
        ),
        (
            &["--sigma-a", "0.1", "--sigma-s", "1", "--r-max", "-3"],
            "--r-max",
        ),
        (
            &["--sigma-a", "0.1", "--sigma-s", "1", "--steps", "1"],
            "--steps",
        ),
    ];
    for (args, flag) in cases {
        let mut all = vec!["--model", "pbd"];
        all.extend_from_slice(args);
        let o = run(&all);
        assert_eq!(o.status.code(), Some(1), "{all:?}");
        assert!(stderr(&o).contains(flag), "{all:?}: {}", stderr(&o));
        assert!(stdout(&o).is_empty());
    }
    // Usage errors (unknown model, unparsable number) are clap's: exit 2, naming the value.
    let o = run(&["--model", "tripole", "--sigma-a", "1", "--sigma-s", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("tripole") && stderr(&o).contains("better-dipole"));
    let o = run(&["--model", "dipole", "--sigma-a", "abc", "--sigma-s", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("sigma-a"));
}

//! The checked-in header `include/het_bssrdf.h` is what cbindgen generates from the crate now
//! (settings in `cbindgen.toml`). After changing the C API, regenerate it with
//! `HET_BSSRDF_BLESS=1 cargo test -p het-bssrdf-capi --test header`.

use std::path::Path;

#[test]
fn header_is_up_to_date() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config =
        cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen parses the crate");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("UTF-8 header");
    let path = crate_dir.join("include/het_bssrdf.h");
    if std::env::var_os("HET_BSSRDF_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write the header");
        return;
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == generated,
        "{} is out of date: regenerate it with \
         `HET_BSSRDF_BLESS=1 cargo test -p het-bssrdf-capi --test header`",
        path.display()
    );
}

/// The header's description of `hb_material_new` names every profile model, scattering order
/// and estimator the library accepts, and no other: the lists are the crates' own
/// (`ProfileModel::ALL`, `Scattering::ALL`, `Estimator::ALL`), so adding an estimator without
/// documenting it in the C API fails here.
#[test]
fn the_header_names_every_choice_the_library_accepts() {
    use bssrdf_core::{ProfileModel, Scattering};
    use het_estimate::Estimator;
    let header =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("include/het_bssrdf.h"))
            .expect("the header");
    let doc = header
        .split("hb_material_new(")
        .next()
        .and_then(|before| before.rsplit("/**").next())
        .expect("the doc comment of hb_material_new")
        .replace("\n * ", " ");
    // The quoted names (`"name"`) in the parenthesis that follows `lead`.
    let listed = |lead: &str| -> Vec<String> {
        let start = doc
            .find(lead)
            .unwrap_or_else(|| panic!("`{lead}` in {doc}"))
            + lead.len();
        let list = &doc[start..start + doc[start..].find(')').expect("a closing parenthesis")];
        let mut names: Vec<String> = list
            .split("`\"")
            .skip(1)
            .filter_map(|s| s.split("\"`").next().map(str::to_string))
            .collect();
        names.sort();
        names
    };
    let sorted = |mut v: Vec<&str>| {
        v.sort();
        v.into_iter().map(str::to_string).collect::<Vec<_>>()
    };
    assert_eq!(
        listed("the profile `model` ("),
        sorted(ProfileModel::ALL.iter().map(|m| m.name()).collect())
    );
    assert_eq!(
        listed("(`scattering`: "),
        sorted(Scattering::ALL.iter().map(|s| s.name()).collect())
    );
    assert_eq!(
        listed("the estimator ("),
        sorted(Estimator::ALL.iter().map(|e| e.name()).collect())
    );
}

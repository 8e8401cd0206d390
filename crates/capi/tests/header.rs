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

//! The README's library example is the `het-estimate` crate documentation's, which
//! `cargo test` compiles and runs as a doctest: the two copies must not drift apart.

/// The first ```` ```rust ```` block after `heading` in `text`.
fn rust_block<'a>(text: &'a str, heading: &str) -> &'a str {
    let from = text.find(heading).map_or(0, |i| i);
    let start = text[from..].find("```rust").expect("a rust block") + from + "```rust".len();
    let end = text[start..].find("```").expect("a closed block") + start;
    &text[start..end]
}

#[test]
fn readme_library_example_is_the_compiled_doctest() {
    let root = include_str!("../README.md");
    let krate = include_str!("../crates/het-estimate/README.md");
    let a = rust_block(root, "## Using the libraries in your renderer");
    let b = rust_block(krate, "");
    assert!(a.contains("impl SurfaceQuery for") && a.contains("fn main()"));
    assert_eq!(
        a, b,
        "README.md's library example differs from het-estimate's README"
    );
}

#!/usr/bin/env python3
"""Builds every example and every README code block as an outside crate would.

A temporary crate outside the workspace depends on the library crates by path only (no
dev-dependencies, no features). Each `examples/*.rs` of the workspace and of every crate is
copied into its `examples/` (with the files it includes through `#[path]`, at the same
relative place), and each ```rust block of README.md and crates/*/README.md becomes an example
of its own, as a reader would paste it. `cargo check --examples` must then succeed: a renderer
author copying any of them gets a program that compiles.

Examples that a crate's manifest gives `required-features` (data tooling such as
bssrdf-core's `tabulate`) are listed as skipped: they are documented as needing the feature.

Usage: python3 .ci/outside_crate.py [--keep]   (run from anywhere; CARGO_TARGET_DIR is honoured)
"""

import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib

ROOT = pathlib.Path(__file__).resolve().parent.parent

# The library crates an outside crate may depend on, under the names the examples use.
DEPENDENCIES = {
    "bssrdf-core": ("crates/bssrdf-core", None),
    "het-estimate": ("crates/het-estimate", None),
    "tracer": ("crates/tracer", "het-bssrdf-tracer"),
    "pipeline": ("crates/pipeline", "het-bssrdf-pipeline"),
    "experiments": ("crates/experiments", "het-bssrdf-experiments"),
    "het-bssrdf": (".", None),
}

PATH_ATTR = re.compile(r'#\[path\s*=\s*"([^"]+)"\]')


def manifest_examples_with_features(crate_dir):
    """Names of the examples whose [[example]] entry has required-features."""
    with open(crate_dir / "Cargo.toml", "rb") as f:
        manifest = tomllib.load(f)
    return {
        e["name"]: e["required-features"]
        for e in manifest.get("example", [])
        if e.get("required-features")
    }


def copy_with_includes(src, dest, out_root, seen):
    """Copies `src` to `dest` and, recursively, the files it names in #[path] attributes, at the
    same place relative to `dest` as they are relative to `src`."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(src, dest)
    for rel in PATH_ATTR.findall(src.read_text()):
        inc_src = (src.parent / rel).resolve()
        inc_dest = pathlib.Path(os.path.normpath(dest.parent / rel))
        if out_root not in inc_dest.parents:
            sys.exit(f"{src}: #[path] {rel} leaves the crate")
        if inc_dest not in seen:
            seen.add(inc_dest)
            copy_with_includes(inc_src, inc_dest, out_root, seen)


def readme_blocks(path):
    """The ```rust blocks of a Markdown file (rust,ignore and other languages excluded)."""
    blocks, current, fence = [], None, None
    for line in path.read_text().splitlines():
        if current is None:
            m = re.match(r"^(\s*)```rust(,no_run)?\s*$", line)
            if m:
                current, fence = [], m.group(1)
        elif line.strip() == "```":
            blocks.append("\n".join(current) + "\n")
            current = None
        else:
            current.append(line[len(fence):] if line.startswith(fence) else line)
    return blocks


def main():
    keep = "--keep" in sys.argv
    tmp = pathlib.Path(tempfile.mkdtemp(prefix="het-bssrdf-outside-"))
    crate = tmp / "outside"
    (crate / "src").mkdir(parents=True)
    (crate / "src" / "lib.rs").write_text("//! An outside crate: the examples are its own.\n")
    deps = []
    for name, (path, package) in DEPENDENCIES.items():
        spec = f'path = "{(ROOT / path).as_posix()}"'
        if package:
            spec += f', package = "{package}"'
        deps.append(f"{name} = {{ {spec} }}")
    (crate / "Cargo.toml").write_text(
        "[package]\n"
        'name = "outside"\n'
        'version = "0.0.0"\n'
        'edition = "2024"\n'
        "publish = false\n\n"
        "[dependencies]\n" + "\n".join(deps) + "\n\n[workspace]\n"
    )
    # The workspace's lock file, so that the same dependency versions resolve offline.
    shutil.copyfile(ROOT / "Cargo.lock", crate / "Cargo.lock")

    examples, skipped = [], []
    seen = set()
    crate_dirs = [ROOT] + sorted(p.parent for p in (ROOT / "crates").glob("*/Cargo.toml"))
    for crate_dir in crate_dirs:
        gated = manifest_examples_with_features(crate_dir)
        prefix = "root" if crate_dir == ROOT else crate_dir.name.replace("-", "_")
        for src in sorted((crate_dir / "examples").glob("*.rs")):
            label = src.relative_to(ROOT).as_posix()
            if src.stem in gated:
                skipped.append(f"{label} (needs feature {', '.join(gated[src.stem])})")
                continue
            dest = crate / "examples" / f"{prefix}_{src.stem}.rs"
            copy_with_includes(src, dest, crate, seen)
            examples.append(label)
    for readme in [ROOT / "README.md"] + sorted((ROOT / "crates").glob("*/README.md")):
        label = readme.relative_to(ROOT).as_posix()
        for k, block in enumerate(readme_blocks(readme)):
            if "fn main" not in block:
                sys.exit(f"{label}: rust block {k + 1} is not a complete program (no fn main)")
            stem = re.sub(r"\W", "_", f"readme_{label}_{k + 1}")
            (crate / "examples" / f"{stem}.rs").write_text(block)
            examples.append(f"{label} block {k + 1}")

    print(f"outside crate at {crate}: {len(examples)} programs")
    for e in examples:
        print(f"  {e}")
    for s in skipped:
        print(f"  skipped: {s}")
    env = dict(os.environ)
    env.setdefault("CARGO_TARGET_DIR", str(ROOT / "target"))
    result = subprocess.run(
        ["cargo", "check", "--examples", "--quiet"], cwd=crate, env=env
    )
    if result.returncode == 0:
        print(f"outside crate: {len(examples)} programs compile")
    if not keep:
        shutil.rmtree(tmp, ignore_errors=True)
    sys.exit(result.returncode)


if __name__ == "__main__":
    main()

#!/usr/bin/env bash
# The Python bindings: build the wheel with maturin in a fresh virtual environment, install
# it there, import it and render checker-slab.toml, then run the pytest suite. The CI machine
# has only python3 and pip, so the venv and its packages (maturin, numpy, pytest) are made
# here. The matplotlib example runs only where matplotlib is already installed.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
python3 -m venv "$tmp/venv"
py="$tmp/venv/bin/python"
"$py" -m pip install --quiet --disable-pip-version-check "maturin>=1.9.4,<2" numpy pytest
# The dev profile: dependencies optimised (the workspace's profile), quick to compile.
"$tmp/venv/bin/maturin" build --locked --quiet -m crates/python/Cargo.toml -o "$tmp/dist"
"$py" -m pip install --quiet --disable-pip-version-check "$tmp"/dist/het_bssrdf-*.whl
# From an unrelated directory, so that the installed wheel is what is imported.
(cd "$tmp" && "$py" - "$root/examples/scenes/checker-slab.toml" <<'PY'
import sys
import numpy as np
import het_bssrdf as hb

r = np.linspace(0.0, 4.0, 9)
values = hb.Profile("pbd", "multiple", 0.0, 1.3).eval(r, 0.01, 1.0)
assert values.shape == r.shape and np.all(np.isfinite(values)) and values[0] > values[-1] > 0
image = hb.render(sys.argv[1], "sone", 1)
assert image.shape == (128, 128, 3) and np.all(np.isfinite(image)) and image.max() > 0
print(f"het_bssrdf {hb.__version__}: profile {values[:3]}, checker-slab {image.shape}, "
      f"mean {image.mean():.4f}")
PY
)
(cd "$tmp" && "$py" -m pytest -q -p no:cacheprovider "$root/crates/python/tests")
if python3 -c "import matplotlib" 2>/dev/null; then
    "$py" -m pip install --quiet --disable-pip-version-check matplotlib
    (cd "$tmp" && "$py" "$root/crates/python/examples/plot_profile.py" "$tmp/profiles.png")
else
    echo "crates/python/examples/plot_profile.py: skipped (matplotlib is not installed)"
fi

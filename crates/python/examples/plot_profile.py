# %% [markdown]
# # Radial profiles of het-bssrdf, plotted with matplotlib
#
# A notebook-style script (cells marked `# %%`, runnable as a plain script or cell by cell in
# an editor that understands the markers). It needs the `het_bssrdf` wheel
# (crates/python/README.md) and matplotlib:
#
#     pip install matplotlib
#     python crates/python/examples/plot_profile.py [output.png]

# %%
import sys

import matplotlib

matplotlib.use("Agg")  # write a file; no display needed
import matplotlib.pyplot as plt
import numpy as np

import het_bssrdf as hb

# %% [markdown]
# R(r) (1/length²) of every profile model for a marble-like medium, σa = 0.01 and σs = 1 per
# unit length, at η = 1.3: r·R(r) on log axes shows where the light comes back out.

# %%
sigma_a, sigma_s, eta = 0.01, 1.0, 1.3
r = np.geomspace(1e-3, 100.0, 400)
fig, ax = plt.subplots(figsize=(7, 4.5))
for model in hb.PROFILE_MODELS:
    profile = hb.Profile(model, scattering="all" if model == "tabulated" else "multiple", eta=eta)
    values = profile.eval(r, sigma_a, sigma_s)
    total = profile.total(sigma_a, sigma_s)
    ax.loglog(r, r * values, label=f"{model} (total {total:.3f})")
ax.set_xlabel("r (length)")
ax.set_ylabel("r R(r) (1/length)")
ax.set_title(f"Radial profiles, σa = {sigma_a}, σs = {sigma_s}, η = {eta}")
ax.legend()
fig.tight_layout()

# %%
out = sys.argv[1] if len(sys.argv) > 1 else "profiles.png"
fig.savefig(out, dpi=120)
print(f"wrote {out}")

"""How much the film-skin inter-reflections beyond path 3 change made-up skin (a benchmark).

    python bench/inter_reflection.py [--out docs/inter_reflection.png]

The paper's path 3 is the first term of the adding equation; the rest (light the skin sends up
that the film's underside, reflecting like its top, sends back down, again and again) is what
``lut_baker.bake.bake(..., inter_reflection=True)`` adds.  For the paper's foundation and each
shade (on the paper's skin, coverage 1) this prints the directional albedo with and without it
and the largest change of the BRDF, and draws both (albedo against incidence; in-plane BRDF
slices at 30 and 60 degrees of incidence).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker import bake  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.numerics.geometry import direction  # noqa: E402

FOUNDATIONS = ("paper_natural", "light_ivory", "medium_beige", "deep_mocha")
CHANNELS = ("R", "G", "B")
COLOURS = ("tab:red", "tab:green", "tab:blue")


def measure(resolution: str = "default") -> dict:
    theta = np.linspace(0.0, 89.0, 90)
    out = {}
    for name in FOUNDATIONS:
        skin = presets.made_up_skin(name)
        tables = bake.bake(skin, resolution, inter_reflection=True)
        albedo = tables.directional_albedo(theta)
        extra = bake.inter_reflection_albedo(skin, theta, resolution)
        nodes = tables.node_values()
        without = nodes - tables.inter_reflection  # coverage 1: the table adds in full
        out[name] = {"theta": theta, "albedo": albedo, "extra": extra, "tables": tables,
                     "brdf_change": tables.inter_reflection / without}
    return out


def in_plane(tables, theta_i_deg: float, theta_o_deg: np.ndarray, with_ir: bool):
    """BRDF in the plane of incidence: theta_o < 0 on the side of the light."""
    wi = direction(np.radians(theta_i_deg), 0.0)
    wo = direction(np.radians(np.abs(theta_o_deg)), np.where(theta_o_deg < 0, 0.0, np.pi))
    if with_ir:
        return tables.made_up_reflection(wi, wo)
    from dataclasses import replace

    return replace(tables, inter_reflection=None).made_up_reflection(wi, wo)


def report(results: dict) -> str:
    lines = ["| foundation | channel | albedo at 0 deg: paths 1+3 | + inter-reflection | "
             "change at 0 / 60 / 89 deg | largest BRDF change | median BRDF change |",
             "|---|---|---|---|---|---|---|"]
    for name, r in results.items():
        theta = r["theta"]
        at = [int(np.argmin(np.abs(theta - t))) for t in (0.0, 60.0, 89.0)]
        for c, channel in enumerate(CHANNELS):
            base, extra = r["albedo"][:, c], r["extra"][:, c]
            change = " / ".join(f"{100 * extra[i] / base[i]:+.1f}%" for i in at)
            brdf = r["brdf_change"][..., c]
            lines.append(f"| {name} | {channel} | {base[at[0]]:.3f} | "
                         f"{base[at[0]] + extra[at[0]]:.3f} | {change} | "
                         f"{100 * brdf.max():+.1f}% | {100 * np.median(brdf):+.1f}% |")
    return "\n".join(lines)


def chart(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(results), figsize=(4.2 * len(results), 7.5),
                             constrained_layout=True)
    theta_o = np.linspace(-89.0, 89.0, 357)
    for column, (name, r) in enumerate(results.items()):
        top, bottom = axes[0, column], axes[1, column]
        for c, colour in enumerate(COLOURS):
            top.plot(r["theta"], r["albedo"][:, c], color=colour, lw=1.5)
            top.plot(r["theta"], r["albedo"][:, c] + r["extra"][:, c], color=colour, lw=1.5,
                     ls="--")
        top.set_title(name)
        top.set_xlabel("incidence theta_i (degrees)")
        top.set_ylabel("directional albedo")
        top.set_ylim(0.0, 1.0)
        top.grid(alpha=0.3)
        for theta_i, width in ((30.0, 1.0), (60.0, 2.0)):
            plain = in_plane(r["tables"], theta_i, theta_o, False)[:, 1]
            full = in_plane(r["tables"], theta_i, theta_o, True)[:, 1]
            bottom.plot(theta_o, plain, color="k", lw=width, label=f"paths 1+3, {theta_i:.0f} deg")
            bottom.plot(theta_o, full, color="tab:orange", lw=width, ls="--",
                        label=f"+ inter-reflection, {theta_i:.0f} deg")
        bottom.set_yscale("log")
        bottom.set_xlabel("in-plane view theta_o (deg; < 0: light side)")
        bottom.set_ylabel("BRDF, green channel (1/sr)")
        bottom.grid(alpha=0.3, which="both")
        if column == 0:
            top.plot([], [], color="k", label="paths 1 + 3 (paper)")
            top.plot([], [], color="k", ls="--", label="+ all inter-reflections")
            top.legend(loc="lower left", fontsize=8)
            bottom.legend(loc="upper left", fontsize=7)
    fig.suptitle("Inter-reflections between the film's underside and the skin (coverage 1, "
                 "paper's skin substitute); solid: the paper's path 3, dashed: the adding sum")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "inter_reflection.png")
    parser.add_argument("--resolution", default="default")
    args = parser.parse_args()
    results = measure(args.resolution)
    print(report(results))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    chart(results, args.out)
    print(f"chart: {args.out}")


if __name__ == "__main__":
    main()

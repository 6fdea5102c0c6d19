"""Round trip of the fits: the paper's protocols synthesised from its parameters with
multiplicative noise, fitted from a poor start, compared with the truth.

    python bench/fit_roundtrip.py [--seeds 20] [--noise 0.02]

Prints, per protocol and parameter: the recovery target (5%; 10% for the dipole), the median
and worst relative error over the seeds, the median relative standard error the fit reports,
the worst error in units of that standard error, how many fits flagged the parameter, and the
time per fit.  Errors and standard errors are relative to the value (eta included).  The
transmission fit is run twice: eta free, and eta held at the same film's reflection fit (one
film, one index: the paper's two fits share eta = 1.19).
"""

# ruff: noqa: E402  (lut_baker is imported after the repository root joins sys.path)
from __future__ import annotations

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from lut_baker.model.presets import paper_layers
from lut_baker.offline.measured.layer_fit import (
    fit_dipole,
    fit_reflection,
    fit_transmission,
    poor_start,
    relative_errors,
)
from lut_baker.offline.measured.measurements import paper_protocols

TARGETS = {"n": 0.05, "eta": 0.05, "P_s/P_d": 0.05, "P_t/P_d": 0.05,
           "sigma_s": 0.10, "sigma_a": 0.10}
"""The recovery targets (relative): what a fit of the paper's protocols should reach."""


def relative_stderrs(result) -> dict[str, float]:
    """Standard errors relative to the value (eta: to eta itself, as the errors are)."""
    out = {name: se / float(getattr(result.params, name)) for name, se in result.stderr.items()}
    out.update({name: se / value for name, (value, se) in result.derived.items()})
    return out


def flagged(result, name: str) -> bool:
    """Whether any warning names the parameter (a ratio: either of its P's)."""
    parts = name.split("/")
    return any(any(w.startswith(p + " ") or f" {p} " in w for p in parts)
               for w in result.warnings)


def run(seeds: int, noise: float):
    film, film_t, skin, dipole = paper_layers()
    records = defaultdict(lambda: defaultdict(list))
    timings = defaultdict(list)
    warnings = defaultdict(lambda: defaultdict(int))
    correlations = defaultdict(list)

    def record(name, truth, fit, *args, **kwargs):
        start = time.perf_counter()
        result = fit(*args, **kwargs)
        timings[name].append(time.perf_counter() - start)
        errors = relative_errors(result.params, truth)
        stderrs = relative_stderrs(result)
        for parameter in TARGETS:
            if parameter in stderrs:
                records[name][parameter].append((errors[parameter], stderrs[parameter],
                                                 flagged(result, parameter)))
        for text in result.warnings:
            warnings[name][text.split(":")[0]] += 1
        correlations[name].append((result.free, result.correlation))
        return result

    for seed in range(seeds):
        data = paper_protocols(noise, seed)
        reflection = record("film reflection", film, fit_reflection, data["film_reflection"],
                            poor_start(film))
        record("film transmission (eta free)", film_t, fit_transmission,
               data["film_transmission"], poor_start(film_t))
        record("film transmission (eta from reflection)", film_t, fit_transmission,
               data["film_transmission"], poor_start(film_t), eta=float(reflection.params.eta))
        record("skin reflection", skin, fit_reflection, data["skin_reflection"],
               poor_start(skin))
        record("skin dipole (d >= 0.1 mm)", dipole, fit_dipole, data["skin_profile"],
               poor_start(dipole), g=float(dipole.g), eta=float(dipole.eta))
    return records, timings, warnings, correlations


def strongest_correlation(runs) -> str:
    """The pair of free parameters with the largest median |correlation| over the seeds."""
    names = runs[0][0]
    median = np.median([c for _, c in runs], axis=0)
    off = np.abs(median) - np.eye(len(names))
    i, j = np.unravel_index(np.argmax(off), off.shape)
    return f"{names[i]}-{names[j]} {median[i, j]:+.3f}"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--noise", type=float, default=0.02)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    records, timings, warnings, correlations = run(args.seeds, args.noise)
    total = time.perf_counter() - start

    print(f"Round trip over {args.seeds} seeds, {100 * args.noise:g}% multiplicative noise, "
          "poor start (x3 and /3 in turn, eta 1.5)\n")
    print("| protocol | parameter | target | median err | worst err | median stderr "
          "| worst err/stderr | flagged | within target |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, parameters in records.items():
        for parameter, rows in parameters.items():
            err = np.abs([r[0] for r in rows])
            se = np.array([r[1] for r in rows])
            flags = sum(r[2] for r in rows)
            target = TARGETS[parameter]
            inside = int(np.sum(err <= target))
            print(f"| {name} | {parameter} | {100 * target:g}% | {100 * np.median(err):.2f}% "
                  f"| {100 * err.max():.2f}% | {100 * np.median(se):.2f}% "
                  f"| {np.max(err / se):.2f} | {flags}/{len(rows)} | {inside}/{len(rows)} |")
    print("\n| protocol | median time per fit | worst | strongest correlation (median) "
          "| warnings (fits) |")
    print("| --- | --- | --- | --- | --- |")
    for name, times in timings.items():
        text = "; ".join(f"{w} ({c})" for w, c in warnings[name].items()) or "none"
        print(f"| {name} | {1000 * np.median(times):.0f} ms | {1000 * max(times):.0f} ms "
              f"| {strongest_correlation(correlations[name])} | {text} |")
    print(f"\ntotal {total:.1f} s for {sum(len(t) for t in timings.values())} fits")
    return 0


if __name__ == "__main__":
    sys.exit(main())

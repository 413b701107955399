#!/usr/bin/env python3
"""Peer check of autoshovel-fuzzy against scikit-fuzzy (not needed by CI).

Builds the paper's §4.3 crawler-tracking controller (inputs e in [-0.45, 0.45]
and ec in [-30, 30], output u in [-2700, 2700] rpm, seven evenly spaced
triangular terms NB..PB on each, the 7 x 7 Table 1 with rows ec and columns e)
in scikit-fuzzy's ControlSystem API with Mamdani min (AND) / min
(implication) / max (aggregation) / centroid, exactly as the Rust crate does:

* output universe np.linspace(-2700, 2700, 201) = our 201 output samples;
* input universes sampled finely enough that every breakpoint is a sample
  (e: 181 points, step 0.005; ec: 121 points, step 0.5), so skfuzzy's
  interpolated fuzzification equals our exact one up to rounding;
* membership functions built with skfuzzy.membership.trimf from the very
  breakpoints our Variable::evenly_spaced_triangles uses (same formula,
  `points` below), the end terms as shoulders [a, a, b] / [a, b, b].

It writes crates/base/fuzzy/tests/data/skfuzzy_table1_surface.csv (columns e, ec,
u on a 21 x 21 grid inside the universes; '#' lines are comments), which
tests/peer_skfuzzy.rs compares with our infer(), and it times
ControlSystemSimulation one input at a time (set inputs, compute, read
output), as a 10 Hz control loop would call it.

Run from the workspace root:
    pip install scikit-fuzzy numpy scipy networkx packaging
    python3 crates/base/fuzzy/peer/skfuzzy_table1.py
"""
import os
import platform
import sys
import time

import numpy as np
import skfuzzy
from skfuzzy import control as ctrl
from skfuzzy.membership import trimf

NAMES = ["NB", "NM", "NS", "ZE", "PS", "PM", "PB"]
# Rows: ec = NB..PB; columns: e = NB..PB; cells: u.
TABLE1 = [
    "NB NB NM NM NS NS ZE",
    "NB NM NM NS NS ZE PS",
    "NM NM NS NS ZE PS PS",
    "NM NS NS ZE PS PS PM",
    "NS NS ZE PS PS PM PM",
    "NS ZE PS PS PM PM PB",
    "ZE PS PS PM PM PB PB",
]
TABLE1 = [row.split() for row in TABLE1]

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "tests", "data", "skfuzzy_table1_surface.csv")


def points(lo, hi, n):
    """Variable::sample: (lo*(n-1-i) + hi*i)/(n-1), ends exact (mirror-exact)."""
    out = []
    for i in range(n):
        if i == 0:
            out.append(float(lo))
        elif i == n - 1:
            out.append(float(hi))
        else:
            out.append((lo * float(n - 1 - i) + hi * float(i)) / float(n - 1))
    return out


def partition(lo, hi, n=7):
    """Breakpoints of Variable::evenly_spaced_triangles (shoulders at the ends)."""
    c = points(lo, hi, n)
    return [[c[max(i - 1, 0)], c[i], c[min(i + 1, n - 1)]] for i in range(n)]


def build(universe_e, universe_ec, universe_u):
    e = ctrl.Antecedent(universe_e, "e")
    ec = ctrl.Antecedent(universe_ec, "ec")
    u = ctrl.Consequent(universe_u, "u", defuzzify_method="centroid")
    for var, (lo, hi) in ((e, (-0.45, 0.45)), (ec, (-30.0, 30.0)), (u, (-2700.0, 2700.0))):
        for name, abc in zip(NAMES, partition(lo, hi)):
            var[name] = trimf(var.universe, abc)
    rules = [
        ctrl.Rule(e[NAMES[c]] & ec[NAMES[r]], u[TABLE1[r][c]])
        for r in range(7)
        for c in range(7)
    ]
    return e, ec, u, rules


def main():
    ue = np.linspace(-0.45, 0.45, 181)
    uec = np.linspace(-30.0, 30.0, 121)
    uu = np.linspace(-2700.0, 2700.0, 201)
    e, ec, u, rules = build(ue, uec, uu)
    system = ctrl.ControlSystem(rules)

    # The operators really are Mamdani min/max/centroid.
    r0 = rules[0]
    assert r0.and_func is np.fmin, r0.and_func
    assert r0.or_func is np.fmax, r0.or_func
    # Consequent default accumulation: skfuzzy's accumulation_max = np.fmax.
    assert u.accumulation_method.__name__ == "accumulation_max", u.accumulation_method
    assert u.accumulation_method(np.array([0.2, 0.7]), np.array([0.5, 0.1])).tolist() == [0.5, 0.7]
    assert u.defuzzify_method == "centroid"
    # Implication is min: CrispValueCalculator.find_memberships clips each
    # consequent term with np.minimum(cut, mf) — hard-wired, no option.

    # automf vs our shoulder partition, on the universe skfuzzy samples.
    probe = ctrl.Antecedent(ue, "probe")
    probe.automf(names=NAMES)
    automf_diff = max(
        float(np.max(np.abs(probe[n].mf - e[n].mf))) for n in NAMES
    )

    # 21 x 21 surface inside the universes.
    sim = ctrl.ControlSystemSimulation(system)
    grid_e = np.linspace(-0.45, 0.45, 21)
    grid_ec = np.linspace(-30.0, 30.0, 21)
    rows = []
    for y in grid_ec:
        for x in grid_e:
            sim.input["e"] = float(x)
            sim.input["ec"] = float(y)
            sim.compute()
            rows.append((float(x), float(y), float(sim.output["u"])))

    # Rate, one input pair per call as a 10 Hz loop would do it.
    rng = np.random.default_rng(7)
    n_calls = 2000
    samples = np.column_stack(
        (rng.uniform(-0.45, 0.45, n_calls), rng.uniform(-30.0, 30.0, n_calls))
    )
    rates = {}
    for label, kwargs in (("default (cache=True)", {}), ("cache=False", {"cache": False})):
        s = ctrl.ControlSystemSimulation(system, **kwargs)
        for x, y in samples[:50]:  # warm-up
            s.input["e"] = float(x)
            s.input["ec"] = float(y)
            s.compute()
        t0 = time.perf_counter()
        for x, y in samples:
            s.input["e"] = float(x)
            s.input["ec"] = float(y)
            s.compute()
            _ = s.output["u"]
        dt = time.perf_counter() - t0
        rates[label] = (n_calls / dt, dt / n_calls * 1e6)

    header = [
        "skfuzzy peer of the autoshovel-fuzzy Table-1 system (paper §4.3)",
        "command: python3 crates/base/fuzzy/peer/skfuzzy_table1.py (from the workspace root)",
        f"python {platform.python_version()}, numpy {np.__version__}, "
        f"scikit-fuzzy {skfuzzy.__version__}, {platform.machine()} {os.cpu_count()} cpus",
        "universes: e linspace(-0.45,0.45,181), ec linspace(-30,30,121), u linspace(-2700,2700,201)",
        "Mamdani: AND np.fmin, implication min (hard-wired), aggregation accumulation_max (np.fmax), centroid",
        f"automf(names=NB..PB) vs our shoulder partition on the e universe: max |diff| = {automf_diff:.3g}",
        f"ControlSystemSimulation rate over {n_calls} distinct random (e, ec), one call at a time:",
    ]
    for label, (rate, us) in rates.items():
        header.append(f"  {label}: {rate:.0f} calls/s, {us:.1f} us/call")
    text = "".join(f"# {line}\n" for line in header)
    print(text, end="")
    with open(OUT, "w") as f:
        f.write(text)
        f.write("e,ec,u\n")
        for x, y, z in rows:
            f.write(f"{x!r},{y!r},{z!r}\n")
    print(f"wrote {len(rows)} rows to {os.path.relpath(OUT)}", file=sys.stderr)


if __name__ == "__main__":
    main()

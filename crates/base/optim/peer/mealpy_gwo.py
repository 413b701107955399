#!/usr/bin/env python3
"""Peer run of mealpy's OriginalGWO on the benchmarks of autoshovel-optim
(not needed by CI).

Runs mealpy.GWO.OriginalGWO on F1 sphere, F5 Rosenbrock, F9 Rastrigin and
F10 Ackley exactly as crates/base/optim/src/benchmarks.rs defines them and with
the setting of Mirjalili, Mirjalili & Lewis 2014 (30 dimensions, 30 wolves,
500 iterations, bounds +-100, +-30, +-5.12, +-32), one run per seed, timing
each run (wall clock, single process, mealpy's default mode 'single'). It
prints a markdown table: mean / std / best of the best fitness over the
seeds and the mean time per run; and it times the dig planner's size
(5-D sphere, 50 wolves x 100 iterations) for the optimiser's own overhead.

Note: mealpy's OriginalGWO differs from Mirjalili's reference code in two
ways: each wolf keeps its old position when the new one is worse (greedy
selection, mode 'single'), and a = 2 - 2 t / T with t = 1..T.

Run from the workspace root, in a virtualenv (mealpy 3.0.3 pins
numpy <= 1.26, which would downgrade a system numpy):
    python3 -m venv /tmp/mealpy-venv && /tmp/mealpy-venv/bin/pip install mealpy
    /tmp/mealpy-venv/bin/python crates/base/optim/peer/mealpy_gwo.py --runs 30
"""
import argparse
import math
import platform
import time

import numpy as np
import mealpy
from mealpy import FloatVar, GWO


def sphere(x):
    return float(np.sum(x * x))


def rosenbrock(x):
    return float(np.sum(100.0 * (x[1:] - x[:-1] ** 2) ** 2 + (x[:-1] - 1.0) ** 2))


def rastrigin(x):
    return float(np.sum(x * x - 10.0 * np.cos(2.0 * math.pi * x) + 10.0))


def ackley(x):
    n = x.size
    return float(
        -20.0 * math.exp(-0.2 * math.sqrt(np.sum(x * x) / n))
        - math.exp(np.sum(np.cos(2.0 * math.pi * x)) / n)
        + 20.0
        + math.e
    )


# (label, name, function, half-width of the box, published GWO mean, std)
FUNCTIONS = [
    ("F1", "sphere", sphere, 100.0, 6.59e-28, 6.34e-5),
    ("F5", "rosenbrock", rosenbrock, 30.0, 26.81258, 69.90499),
    ("F9", "rastrigin", rastrigin, 5.12, 0.310521, 47.35612),
    ("F10", "ackley", ackley, 32.0, 1.06e-13, 0.077835),
]


def run(f, b, dim, pop, epochs, seed):
    problem = {
        "obj_func": f,
        "bounds": FloatVar(lb=(-b,) * dim, ub=(b,) * dim),
        "minmax": "min",
        "log_to": None,
    }
    model = GWO.OriginalGWO(epoch=epochs, pop_size=pop)
    t0 = time.perf_counter()
    best = model.solve(problem, seed=seed)
    return best.target.fitness, time.perf_counter() - t0


def stats(values):
    m = sum(values) / len(values)
    s = math.sqrt(sum((v - m) ** 2 for v in values) / (len(values) - 1)) if len(values) > 1 else 0.0
    return m, s, min(values)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=30, help="seeds per function")
    args = ap.parse_args()
    print(f"mealpy {mealpy.__version__}, numpy {np.__version__}, Python {platform.python_version()}, "
          f"{platform.machine()} {platform.system()}")
    print(f"OriginalGWO, 30 dimensions, 30 wolves, 500 iterations, seeds 0..{args.runs}\n")
    print("| function | published mean (std) | mealpy: mean / std / best | ms per run |")
    print("|---|---|---|---|")
    for label, name, f, b, pub_mean, pub_std in FUNCTIONS:
        values, times = [], []
        for seed in range(args.runs):
            v, t = run(f, b, 30, 30, 500, seed)
            values.append(v)
            times.append(t)
        m, s, best = stats(values)
        print(f"| {label} {name} | {pub_mean:.3e} ({pub_std:.3e}) | {m:.3e} / {s:.2e} / {best:.3e} "
              f"| {1e3 * sum(times) / len(times):.0f} |", flush=True)
    times = [run(sphere, 100.0, 5, 50, 100, seed)[1] for seed in range(10)]
    print(f"\n5-D sphere, 50 wolves x 100 iterations: {1e3 * sum(times) / len(times):.1f} ms per run")


if __name__ == "__main__":
    main()

"""From a LAZ scan to a dig plan, in Python (crates/front/py/README.md).

    python crates/front/py/examples/dig_from_scan.py [SCAN.laz] [--png dig.png]

Without a scan, one is generated at the paper's 1:30 scale (the planner's
built-in machine is the 1:30 model) and written as LAZ first.
"""

import argparse
import os
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import autoshovel  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("scan", nargs="?", help="a .laz/.las/.pcd/.ply scan of a muck pile")
    ap.add_argument("--png", default="dig.png")
    a = ap.parse_args(argv)

    scan = a.scan
    if scan is None:
        scan = os.path.join(tempfile.mkdtemp(), "pile.laz")
        autoshovel.write_cloud(scan, autoshovel.generate_pile("typical", 200_000, scale=1 / 30, seed=1))

    points = autoshovel.read_cloud(scan)  # (N, 3) float32
    seen = autoshovel.perceive(points)  # the §3 pipeline
    print(f"{len(points):,} points -> {seen.output_points:,} kept, roll {seen.roll_deg:.2f}°, pitch {seen.pitch_deg:.2f}°, R² {seen.r2:.3f}")

    plan = autoshovel.plan_dig(seen)  # GWO + CMA-ES under c1–c18
    if not plan.success:
        print(f"no feasible plan: {plan.error}")
        return 1
    print(f"dig: {plan.m_dig_kg:.2f} kg in {plan.td_s:.2f} s, fill {100 * plan.fill_factor:.0f} %, f {plan.f:.3f}")

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    cleaned = seen.points
    left.scatter(cleaned[:, 0], cleaned[:, 2], s=0.2, c="0.6", label="cleaned scan")
    left.set(xlabel="x [m]", ylabel="z [m]", title="scan (levelled)")
    right.plot(*plan.pile_profile.T, color="0.4", label="pile profile")
    right.plot(plan.tooth_path[:, 1], plan.tooth_path[:, 2], color="C3", label="tooth path")
    right.set(xlabel="x [m]", ylabel="y [m]", title="dig plan (dig frame)", aspect="equal")
    right.legend()
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"wrote {a.png}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

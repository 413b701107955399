"""laspy as the independent reader and writer of LAS for tests/real_scans.rs.

  las_peer.py wide IN OUT      write OUT: IN's points and a copy of them
                               12 km east, at 1 mm steps (a survey more than
                               10 km across), with every attribute and IN's CRS
  las_peer.py same IN OUT      OUT holds exactly IN's points: every
                               coordinate within half the file's scale, the
                               same CRS, point format, version and attributes
  las_peer.py subset IN OUT    every point of OUT is a point of IN with all
                               its attributes (the rows a removal filter kept)
  las_peer.py copy IN OUT      OUT: IN's points as plain LAS, in IN's order
  las_peer.py shuffle IN OUT   OUT: IN's points as plain LAS, shuffled
                               (numpy's generator, seed 1)
  las_peer.py values IN OUT    OUT has IN's points in IN's order, every
                               coordinate within 1e-6 and every dimension
                               of IN equal, whatever OUT's header (a trip
                               through a format with no CRS)
  las_peer.py range IN OUT CLASS ZMIN
                               OUT is exactly IN's rows of classification CLASS
                               with z >= ZMIN, in order (filter --range)
  las_peer.py change LATER EARLIER CELLS
                               fill, cut and net volume from EARLIER to LATER
                               on LATER's mean-height grid of CELLS point
                               spacings, each axis in metres by pyproj (a
                               compound CRS's z in its vertical unit)
  las_peer.py tiles IN TILE...
                               every TILE (perceive --tiles) is in IN's CRS
                               and inside IN's bounds (give or take 5 m)
  las_peer.py volume IN BASE CELLS [CLASS]
                               the volume above z = BASE (m) of IN's mean-height
                               grid, cells CELLS point spacings wide, the points
                               at or above BASE only, in metres by pyproj's
                               unit of IN's CRS (perceive with every filter off);
                               with CLASS, of the points of that classification
                               alone (perceive's [range] Classification[C:C])

Prints one JSON line; exits 1 with the first difference.
"""
import json
import sys

import laspy
import numpy as np

# The copy's shift east (m): with the original, a survey 13 km across.
SHIFT_M = 12_000.0
# Steps of the wide survey (m): the finest in common use.
WIDE_SCALE = 0.001


def fail(msg):
    print(json.dumps({"ok": False, "why": msg}))
    sys.exit(1)


def dims(las):
    return [d for d in las.point_format.dimension_names if d not in ("X", "Y", "Z")]


def wide(src, dst):
    a = laspy.read(src)
    h = laspy.LasHeader(point_format=a.header.point_format, version=a.header.version)
    h.scales = np.array([WIDE_SCALE] * 3)
    h.offsets = np.round(a.header.mins)
    for v in a.header.vlrs:
        h.vlrs.append(v)
    out = laspy.LasData(h)
    n = len(a.points)
    for d in dims(a):
        col = np.asarray(a[d])
        out[d] = np.concatenate([col, col])
    out.x = np.concatenate([a.x, a.x + SHIFT_M])
    out.y = np.concatenate([a.y, a.y])
    out.z = np.concatenate([a.z, a.z])
    out.write(dst)
    b = laspy.read(dst)
    span = float(b.header.maxs[0] - b.header.mins[0])
    print(json.dumps({"ok": True, "points": 2 * n, "span_m": span}))


def table(las):
    """Every point's record as a tuple: integer X, Y, Z and every attribute."""
    cols = [np.asarray(las.X), np.asarray(las.Y), np.asarray(las.Z)]
    cols += [np.asarray(las[d]) for d in dims(las)]
    return cols


def header_same(a, b):
    ha, hb = a.header, b.header
    if ha.point_format.id != hb.point_format.id:
        fail(f"point format {hb.point_format.id}, the input's is {ha.point_format.id}")
    if str(ha.version) != str(hb.version):
        fail(f"version {hb.version}, the input's is {ha.version}")
    if not np.allclose(ha.scales, hb.scales, rtol=0, atol=0):
        fail(f"scales {hb.scales}, the input's are {ha.scales}")
    ca, cb = ha.parse_crs(), hb.parse_crs()
    if (ca is None) != (cb is None) or (ca is not None and not ca.equals(cb)):
        fail(f"CRS {cb}, the input's is {ca}")
    if dims(a) != dims(b):
        fail(f"dimensions {dims(b)}, the input's are {dims(a)}")


def same(src, dst):
    a, b = laspy.read(src), laspy.read(dst)
    header_same(a, b)
    if len(a.points) != len(b.points):
        fail(f"{len(b.points)} points, the input has {len(a.points)}")
    worst = 0.0
    for ax, s in zip("xyz", a.header.scales):
        d = float(np.max(np.abs(np.asarray(getattr(a, ax)) - np.asarray(getattr(b, ax)))))
        worst = max(worst, d / s)
        if d > s / 2:
            fail(f"{ax} moved by {d}, more than half the scale {s}")
    for d in dims(a):
        if not np.array_equal(np.asarray(a[d]), np.asarray(b[d])):
            fail(f"attribute {d} differs")
    crs = a.header.parse_crs()
    print(json.dumps({"ok": True, "points": len(b.points), "worst_steps": worst,
                      "epsg": crs.to_epsg() if crs else None}))


def subset(src, dst):
    a, b = laspy.read(src), laspy.read(dst)
    header_same(a, b)
    rows_a = set(zip(*[c.tolist() for c in table(a)]))
    rows_b = list(zip(*[c.tolist() for c in table(b)]))
    missing = [r for r in rows_b if r not in rows_a]
    if missing:
        fail(f"{len(missing)} of {len(rows_b)} points are not the input's, e.g. {missing[0]}")
    print(json.dumps({"ok": True, "points": len(rows_b), "of": len(a.points)}))


def ranged(src, dst, klass, zmin):
    """OUT is exactly IN's rows of classification KLASS with z >= ZMIN, in order."""
    a, b = laspy.read(src), laspy.read(dst)
    header_same(a, b)
    keep = (np.asarray(a.classification) == int(klass)) & (np.asarray(a.z) >= float(zmin))
    want = list(zip(*[np.asarray(c)[keep].tolist() for c in table(a)]))
    got = list(zip(*[c.tolist() for c in table(b)]))
    if want != got:
        fail(f"{len(got)} points, numpy selects {len(want)} (or the rows differ)")
    print(json.dumps({"ok": True, "points": len(got), "of": len(a.points)}))


def values(src, dst):
    a, b = laspy.read(src), laspy.read(dst)
    if len(a.points) != len(b.points):
        fail(f"{len(b.points)} points, the input has {len(a.points)}")
    for ax in "xyz":
        d = float(np.max(np.abs(np.asarray(getattr(a, ax)) - np.asarray(getattr(b, ax)))))
        if d > 1e-6:
            fail(f"{ax} moved by {d}")
    for d in dims(a):
        if d not in dims(b):
            fail(f"dimension {d} is gone")
        if not np.array_equal(np.asarray(a[d]), np.asarray(b[d])):
            fail(f"attribute {d} differs")
    print(json.dumps({"ok": True, "points": len(b.points)}))


def volume(src, base, cells, klass=None):
    a = laspy.read(src)
    crs = a.header.parse_crs()
    unit = crs.axis_info[0].unit_conversion_factor if crs is not None else 1.0
    x, y, z = (np.asarray(getattr(a, ax), dtype=np.float64) * unit for ax in "xyz")
    if klass is not None:
        mine = np.asarray(a.classification) == int(klass)
        x, y, z = x[mine], y[mine], z[mine]
    spacing = np.sqrt((x.max() - x.min()) * (y.max() - y.min()) / len(x))
    base = float(base)
    keep = z >= base
    x, y, z = x[keep], y[keep], z[keep]
    cell = float(cells) * spacing
    ix = np.floor((x - x.min()) / cell).astype(np.int64)
    iy = np.floor((y - y.min()) / cell).astype(np.int64)
    nx = int(np.floor((x.max() - x.min()) / cell)) + 1
    flat = iy * nx + ix
    sums = np.bincount(flat, weights=z)
    counts = np.bincount(flat)
    seen = counts > 0
    mean = sums[seen] / counts[seen]
    v = float(np.sum(np.maximum(mean - base, 0.0)) * cell * cell)
    print(json.dumps({"ok": True, "volume_m3": v, "unit_m": unit, "cells": int(seen.sum()),
                      "kept": int(keep.sum())}))


def metres(a):
    """x, y, z of a LAS file in metres, each axis by pyproj's unit for it
    (a compound CRS's vertical unit for z)."""
    crs = a.header.parse_crs()
    axes = crs.axis_info if crs is not None else []
    unit = [ax.unit_conversion_factor for ax in axes] or [1.0]
    f = [unit[0], unit[min(1, len(unit) - 1)], unit[2] if len(unit) > 2 else unit[0]]
    return [np.asarray(getattr(a, ax), dtype=np.float64) * k for ax, k in zip("xyz", f)]


def change(later, earlier, cells):
    """Fill, cut and net from EARLIER to LATER on LATER's mean-height grid."""
    x, y, z = metres(laspy.read(later))
    ex, ey, ez = metres(laspy.read(earlier))
    spacing = np.sqrt((x.max() - x.min()) * (y.max() - y.min()) / len(x))
    cell = float(cells) * spacing
    nx = int(np.floor((x.max() - x.min()) / cell)) + 1
    ny = int(np.floor((y.max() - y.min()) / cell)) + 1

    def grid(px, py, pz):
        ix = np.floor((px - x.min()) / cell).astype(np.int64)
        iy = np.floor((py - y.min()) / cell).astype(np.int64)
        inside = (ix >= 0) & (ix < nx) & (iy >= 0) & (iy < ny)
        flat = (iy * nx + ix)[inside]
        sums = np.bincount(flat, weights=pz[inside], minlength=nx * ny)
        counts = np.bincount(flat, minlength=nx * ny)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)

    d = grid(x, y, z) - grid(ex, ey, ez)
    d = d[np.isfinite(d)] * cell * cell
    fill, cut = float(d[d > 0].sum()), float(-d[d < 0].sum())
    print(json.dumps({"ok": True, "fill_m3": fill, "cut_m3": cut, "net_m3": fill - cut,
                      "cells_compared": int(d.size)}))


def tiles(src, *outs):
    """Every tile is in SRC's CRS and inside SRC's bounds, give or take the
    5 m that smoothing may move a point (the survey's own coordinates, not
    less an origin of hundreds of kilometres)."""
    a = laspy.read(src)
    crs = a.header.parse_crs()
    lo, hi = a.header.mins, a.header.maxs
    n = 0
    for t in outs:
        b = laspy.read(t)
        if b.header.parse_crs() != crs:
            fail(f"{t}: CRS {b.header.parse_crs()} is not the survey's {crs}")
        for k, ax in enumerate("xyz"):
            v = np.asarray(getattr(b, ax))
            if v.min() < lo[k] - 5.0 or v.max() > hi[k] + 5.0:
                fail(f"{t}: {ax} spans {v.min()}..{v.max()}, the survey {lo[k]}..{hi[k]}")
        n += len(b.points)
    print(json.dumps({"ok": True, "tiles": len(outs), "points": n}))


def tile_attributes(src, *outs):
    """Every point of every tile is a point of SRC, attributes and all: its
    coordinates on SRC's grid (X, Y, Z) and every other dimension of SRC's
    point format equal one of SRC's points at those coordinates (a filter
    that keeps points moves none; duplicates may differ in attributes)."""
    a = laspy.read(src)
    dims = [d for d in a.point_format.dimension_names if d not in ("X", "Y", "Z")]
    scales, offsets = a.header.scales, a.header.offsets

    def rows(las):
        ints = [np.rint((np.asarray(getattr(las, ax)) - offsets[k]) / scales[k]).astype(np.int64)
                for k, ax in enumerate("xyz")]
        cols = [np.asarray(las[d]) for d in dims]
        return [tuple(int(v[i]) for v in ints) + tuple(c[i].tolist() for c in cols) for i in range(len(las.points))]

    have = set(rows(a))
    n = 0
    for t in outs:
        b = laspy.read(t)
        if b.header.point_format.id != a.header.point_format.id:
            fail(f"{t}: point format {b.header.point_format.id}, the survey's {a.header.point_format.id}")
        got = rows(b)
        missing = [r for r in got if r not in have]
        if missing:
            fail(f"{t}: {len(missing)} of {len(got)} points are no survey point with these attributes, e.g. {missing[0]} ({dims})")
        n += len(got)
    print(json.dumps({"ok": True, "tiles": len(outs), "points": n, "dimensions": dims}))


def copy(src, dst, shuffle=False):
    a = laspy.read(src)
    h = laspy.LasHeader(point_format=a.header.point_format.id, version="1.4")
    h.scales, h.offsets = a.header.scales, a.header.offsets
    for v in a.header.vlrs:
        if v.user_id not in ("copc", "laszip encoded"):
            h.vlrs.append(v)
    out = laspy.LasData(h)
    order = np.random.default_rng(1).permutation(len(a.points)) if shuffle else np.arange(len(a.points))
    for d in a.point_format.dimension_names:
        out[d] = np.asarray(a[d])[order]
    out.write(dst)
    print(json.dumps({"ok": True, "points": len(order), "shuffled": shuffle}))


if __name__ == "__main__":
    modes = {"wide": wide, "same": same, "subset": subset, "copy": copy, "volume": volume, "values": values,
             "range": ranged, "change": change, "tiles": tiles,
             "tile-attributes": tile_attributes,
             "shuffle": lambda i, o: copy(i, o, shuffle=True)}
    modes[sys.argv[1]](*sys.argv[2:])

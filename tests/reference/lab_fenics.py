#!/usr/bin/python3
"""An independent reference for plume's virtual lab: the mesoscale model of
Jouve's thesis (chapter 5) solved with FEniCS (legacy dolfin, Debian's
python3-dolfin) on quadratic triangles, and plume's slopes checked against it.

Written from the thesis, not from plume:
- the sample is the rectangle [0, W] x [0, H], bottom edge clamped, top edge
  moved by d along y, sides free (eq. 4.2);
- the mesoscale model (section 5.2, Figure 5.2): bands parallel to the barbs,
  barbs (E_B) of width Phi_B T and barbules (E_b) between them, isotropic
  St-Venant-Kirchhoff with zero Poisson ratio, so the second Piola-Kirchhoff
  stress is S = E * Egl with Egl = (F^T F - I) / 2 (eq. 4.1 with
  E_vv = E_ww = E_vw = E); the pure chapter-5 model: no compression term;
- measured strain eps = ((1 + d/H)^2 - 1) / 2 and stress
  sigma = H f / (b W (H + d)) (section 3.3, f the clamp force);
- the slope: least squares through the origin over the evenly spaced strains,
  the samples weighted by Simpson's rule so that it is the continuous fit whose
  value eq. 5.5 gives in closed form (appendix C.1, eq. C.7).

The band mesh is built here with dolfin's MeshEditor: rows of nodes along lines
parallel to the barbs (every band edge, a few rows inside each band and a row
through every corner of the rectangle), each clipped to the rectangle, and
triangles zipped between consecutive rows, so every band edge is a mesh edge
and every triangle lies in one band.

The band pattern follows plume's documented convention (include/plume/lab.h,
plume_band_def.phase): barb bands centred at (k + 1/2 + phase) T across the
barbs from the sample's corner lowest in that direction. The two possible
orientations of "across" give the same test (the sample turned by 180 degrees).

Checks (exit 1 on failure):
1. the reference itself: longitudinal slope against eq. 5.2 (1e-9; every band
   is strained uniformly, any mesh is exact), transverse slope against the
   rigid-barb stress eq. 5.4 fitted at the same strains (2e-4: the stiff barbs
   stretch, 1e-5 at E_B / E_b = 1e4 in the thesis's Figure 5.4) and against the
   closed form eq. 5.5 (2e-3: Simpson's rule on 10 steps);
2. the tilted reference converged: its slope on the finer mesh within 0.2 % of
   the coarser one;
3. plume (`plume lab traction`, compression_coefficient 0) against the
   reference: longitudinal and transverse to 1e-4, tilted to TILTED_TOLERANCE
   (4000 elements, the calibration's mesh) and TILTED_FINE_TOLERANCE (16000).

Usage: lab_fenics.py --plume build/plume [--quick]
Without dolfin it prints why and exits 0 (skipped).
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

try:
    import dolfin as df
except ImportError as exc:  # pragma: no cover - depends on the machine
    print("lab_fenics: SKIPPED: dolfin (Debian's python3-dolfin) is not installed (%s)" % exc)
    sys.exit(0)

import numpy as np

df.set_log_level(df.LogLevel.WARNING)
df.parameters["form_compiler"]["cpp_optimize"] = True

# Thesis Table 5.1, Phi_B = 0.14.
PHI = 0.14
E_B = 2.57e9
E_b = 3.92e4
PERIOD = 4e-4
THICKNESS = 1.2e-4
# The tilted test of the calibration: 4 mm x 5.2 mm (aspect 1.3), 10 barbs, 45 degrees.
# eps_max = 0.1: the pure St-Venant-Kirchhoff bands are well posed there (Newton fails
# past eps ~ 0.20 in this test, in plume and in dolfin alike: barbule cells are compressed
# past the material's limit point).
TILTED_STRAIN_MAX = 0.1
# plume's tilted slope against the reference. Both are quadratic-element solutions of
# the same problem; what separates them is discretisation error. Measured (docs/lab.md):
# the reference moves by 0.06 % from 9804 to 21734 cells; plume's 4000-element sample is
# 0.27 % above the 21734-cell reference and its 16000-element one 0.0065 %, so plume
# converges to it. 1 % on the 4000-element sample leaves room for that mesh error without letting a
# wrong model pass: a 1 % error in the tilted slope is ~1.2 % in the calibrated E_vw at
# this strain (relative sensitivity 0.85, issue #16).
TILTED_TOLERANCE = 1e-2
# plume on a 16000-element sample: measured 6.5e-5 from the 21734-cell reference (3e-4
# from a 38320-cell one); 1e-3 is the reference's own 9804-to-21734 change (6.2e-4) with
# some room.
TILTED_FINE_TOLERANCE = 1e-3


def simpson_weights(count):
    """Composite Simpson weights on count evenly spaced samples (trapezoid if count - 1 is odd)."""
    n = count - 1
    w = np.zeros(count)
    if n % 2 == 0:
        w[0] = w[-1] = 1.0
        w[1:-1:2] = 4.0
        w[2:-1:2] = 2.0
    else:
        w[:] = 2.0
        w[0] = w[-1] = 1.0
    return w


def fitted_slope(strain, stress):
    w = simpson_weights(len(strain))
    strain = np.asarray(strain)
    stress = np.asarray(stress)
    return float(np.sum(w * strain * stress) / np.sum(w * strain * strain))


def eq_5_2():
    return PHI * E_B + (1.0 - PHI) * E_b


def eq_5_4(strain):
    """Rigid-barb transverse stress, thesis eq. 5.4, lambda = sqrt(2 eps + 1)."""
    lam = math.sqrt(2.0 * strain + 1.0)
    if strain == 0.0:
        return 0.0
    return E_b * (PHI - lam) * ((PHI - lam) ** 2 - (PHI - 1.0) ** 2) / (2.0 * lam * (PHI - 1.0) ** 3)


def eq_5_5(strain_max):
    """Closed-form slope of eq. 5.4 over [0, strain_max], thesis eq. 5.5."""
    p, lm = PHI, math.sqrt(2.0 * strain_max + 1.0)
    num = -15 * p * p * lm - 25 * p * p + 18 * p * lm * lm + 39 * p * lm + 23 * p
    return E_b * (num / (5 * (p - 1) ** 3 * (lm + 1) ** 3) - 1.0 / (p - 1) ** 3)


# ---------------------------------------------------------------------------
# Band mesh


def band_levels(W, H, theta, phase=0.0, barb_rows=2, barbule_rows=4):
    """Offsets across the barbs of the band edges and of the rows inside each band."""
    across = np.array([math.cos(theta), -math.sin(theta)])
    corners = np.array([[0.0, 0.0], [W, 0.0], [W, H], [0.0, H]])
    t_corner = corners @ across
    t_min, t_max = t_corner.min(), t_corner.max()
    levels = []
    half = 0.5 * PHI * PERIOD
    k = -1
    while True:
        centre = t_min + (k + 0.5 + phase) * PERIOD
        if centre - PERIOD > t_max:
            break
        lo, hi = centre - half, centre + half
        nxt = centre + PERIOD - half
        levels += list(np.linspace(lo, hi, barb_rows + 1))
        levels += list(np.linspace(hi, nxt, barbule_rows + 1))
        k += 1
    return levels


def band_mesh(W, H, theta, h, phase=0.0, barb_rows=2, barbule_rows=4):
    """Triangulates [0, W] x [0, H] with rows of nodes along the barbs (angle theta to y).

    Returns the mesh and a numpy array, per cell, 1 in a barb band and 0 in a barbule band.
    """
    levels = band_levels(W, H, theta, phase, barb_rows, barbule_rows)
    mesh, P, C = aligned_mesh(W, H, theta, h, levels)
    across = np.array([math.cos(theta), -math.sin(theta)])
    t_min = (np.array([[0.0, 0.0], [W, 0.0], [W, H], [0.0, H]]) @ across).min()
    centroid_t = P[C].mean(axis=1) @ across
    offset = np.mod(centroid_t - t_min - phase * PERIOD, PERIOD) / PERIOD
    barb = (np.abs(offset - 0.5) < 0.5 * PHI).astype(int)
    return mesh, barb


def aligned_mesh(W, H, theta, h, levels):
    """Triangulates [0, W] x [0, H] with rows of nodes along the barbs (angle theta to y).

    levels: offsets across the barbs (t = p . across) where a row must lie; rows are added
    through every corner of the rectangle. Nodes along a row are about h apart. Returns the
    dolfin mesh, its points and its cells (numpy arrays).
    """
    along = np.array([math.sin(theta), math.cos(theta)])  # the barbs' direction
    across = np.array([math.cos(theta), -math.sin(theta)])
    corners = np.array([[0.0, 0.0], [W, 0.0], [W, H], [0.0, H]])
    t_corner = corners @ across
    t_min, t_max = t_corner.min(), t_corner.max()
    eps = 1e-12 * max(W, H)

    # A row closer than 1 % of a period to a corner's row is moved onto it: at band phase 1/2
    # of the tilted sample a band edge passes 0.1 % of a period from a corner, and the sliver
    # row of cells between them stalls Newton. Moving a band edge by 0.4 um changes that
    # band's width by 0.7 % of a barb, along the few cells that end at the corner.
    merge = 0.01 * PERIOD
    levels = [t for t in levels if np.min(np.abs(t_corner - t)) >= merge] + list(t_corner)
    levels = sorted(t for t in levels if t_min - eps <= t <= t_max + eps)
    rows_t = []
    for t in levels:
        t = min(max(t, t_min), t_max)
        if not rows_t or t - rows_t[-1] > 1e-9 * PERIOD:
            rows_t.append(t)

    def clip(t):
        # p = t across + s along inside the rectangle: the s range.
        lo, hi = -np.inf, np.inf
        base = t * across
        for axis, size in ((0, W), (1, H)):
            a, b = along[axis], base[axis]
            if abs(a) < 1e-14:
                continue
            s0, s1 = (0.0 - b) / a, (size - b) / a
            lo, hi = max(lo, min(s0, s1)), min(hi, max(s0, s1))
        return base, lo, hi

    points, rows = [], []
    for t in rows_t:
        base, lo, hi = clip(t)
        length = max(hi - lo, 0.0)
        count = 1 if length < 1e-9 * PERIOD else max(2, int(math.ceil(length / h)) + 1)
        index = []
        for s in np.linspace(lo, hi, count) if count > 1 else [0.5 * (lo + hi)]:
            p = base + s * along
            p = np.clip(p, [0.0, 0.0], [W, H])
            index.append(len(points))
            points.append(p)
        rows.append(index)

    cells = []
    for a, b in zip(rows[:-1], rows[1:]):
        # Zipper: advance along the row whose next node is further behind.
        i = j = 0
        while i < len(a) - 1 or j < len(b) - 1:
            advance_a = j == len(b) - 1 or (
                i < len(a) - 1 and (i + 1) / max(len(a) - 1, 1) <= (j + 1) / max(len(b) - 1, 1))
            if advance_a:
                cells.append((a[i], a[i + 1], b[j]))
                i += 1
            else:
                cells.append((a[i], b[j], b[j + 1]))
                j += 1

    mesh = df.Mesh()
    editor = df.MeshEditor()
    editor.open(mesh, "triangle", 2, 2)
    editor.init_vertices(len(points))
    for i, p in enumerate(points):
        editor.add_vertex(i, p)
    editor.init_cells(len(cells))
    for i, c in enumerate(cells):
        editor.add_cell(i, np.array(c, dtype=np.uintp))
    editor.close()

    P = np.array(points)
    C = np.array(cells)
    area = 0.5 * np.abs(np.cross(P[C[:, 1]] - P[C[:, 0]], P[C[:, 2]] - P[C[:, 0]]))
    if abs(area.sum() - W * H) > 1e-9 * W * H or area.min() <= 0.0:
        raise RuntimeError("aligned mesh does not tile the sample (area %g of %g, smallest cell %g)"
                           % (area.sum(), W * H, area.min()))
    return mesh, P, C


# ---------------------------------------------------------------------------
# Traction test


def clamped_traction(V, u, energy, W, H, strain_max, steps, absolute_tolerance, relative_tolerance,
                     uniform_start=False):
    """The traction test of section 3.3 on the energy of the field u in V: the bottom edge
    clamped, the top edge moved along y, the sides free. Returns the measured strains and
    stresses (eq. 4.2 and section 3.3), the first pair (0, 0). With uniform_start, the first
    step starts from the uniform stretch rather than from the clamp's displacement alone."""
    residual = df.derivative(energy, u, df.TestFunction(V))
    jacobian = df.derivative(residual, u, df.TrialFunction(V))

    def bottom(x, on_boundary):
        return on_boundary and x[1] < 1e-9 * H

    def top(x, on_boundary):
        return on_boundary and x[1] > H * (1.0 - 1e-9)

    lift = df.Constant((0.0, 0.0))
    bcs = [df.DirichletBC(V, df.Constant((0.0, 0.0)), bottom), df.DirichletBC(V, lift, top)]
    # The clamp force: the residual tested with a field that is (0, 1) on the top edge.
    probe = df.Function(V)
    df.DirichletBC(V, df.Constant((0.0, 1.0)), top).apply(probe.vector())
    force_form = df.derivative(energy, u, probe)

    problem = df.NonlinearVariationalProblem(residual, u, bcs, jacobian)
    solver = df.NonlinearVariationalSolver(problem)
    prm = solver.parameters["newton_solver"]
    prm["report"] = bool(os.environ.get("LAB_FENICS_VERBOSE"))
    prm["linear_solver"] = "mumps"
    prm["absolute_tolerance"] = absolute_tolerance
    prm["relative_tolerance"] = relative_tolerance
    prm["maximum_iterations"] = 30

    strains, stresses = [0.0], [0.0]
    d_prev = 0.0
    for i in range(1, steps + 1):
        strain = strain_max * i / steps
        d = H * (math.sqrt(1.0 + 2.0 * strain) - 1.0)
        # Predictor: the previous field scaled to the new clamp displacement.
        if d_prev > 0.0:
            u.vector()[:] = u.vector().get_local() * (d / d_prev)
        elif uniform_start:
            u.assign(df.interpolate(df.Expression(("0.0", "d * x[1] / H"), d=d, H=H, degree=1), V))
        lift.assign(df.Constant((0.0, d)))
        solver.solve()
        f = df.assemble(force_form)
        strains.append(strain)
        stresses.append(H * f / (THICKNESS * W * (H + d)))
        d_prev = d
    return strains, stresses


def traction(W, H, theta, strain_max, steps, h, barb_rows=2, barbule_rows=4, phase=0.0):
    """Slope (Pa) of the mesoscale traction test, and the mesh size in cells."""
    mesh, barb = band_mesh(W, H, theta, h, phase, barb_rows, barbule_rows)
    V0 = df.FunctionSpace(mesh, "DG", 0)
    modulus = df.Function(V0)
    values = np.empty(mesh.num_cells())
    dofs = np.array([V0.dofmap().cell_dofs(c)[0] for c in range(mesh.num_cells())])
    values[dofs] = np.where(barb == 1, E_B, E_b)
    modulus.vector().set_local(values)
    modulus.vector().apply("insert")
    V = df.VectorFunctionSpace(mesh, "CG", 2)
    u = df.Function(V)
    I = df.Identity(2)
    F = I + df.grad(u)
    Egl = 0.5 * (F.T * F - I)
    # Energy per unit reference area: b (E / 2) Egl : Egl (St-Venant-Kirchhoff, nu = 0).
    energy = THICKNESS * 0.5 * modulus * df.inner(Egl, Egl) * df.dx
    # Round-off in the residual scales with the stiff bands: E_B b W times 1e-16 per term.
    strains, stresses = clamped_traction(V, u, energy, W, H, strain_max, steps, 1e-12 * E_B * THICKNESS * W, 1e-9)
    return fitted_slope(strains, stresses), mesh.num_cells(), strains, stresses


# ---------------------------------------------------------------------------
# plume


def plume_slope(plume, scratch, name, W, H, theta_deg, strain_max, steps, elements, tolerance=None):
    lab = {
        "sample": {"width": W, "height": H, "thickness": THICKNESS, "barb_angle_deg": theta_deg,
                   "elements": elements},
        "material": {"model": "mesoscale", "E_B": E_B, "E_b": E_b, "barb_fraction": PHI,
                     "band_period": PERIOD, "compression_coefficient": 0},
        "traction": {"strain_max": strain_max, "steps": steps},
    }
    if tolerance is not None:
        lab["traction"]["tolerance"] = tolerance
    path = os.path.join(scratch, name + ".json")
    with open(path, "w") as f:
        json.dump(lab, f)
    out = os.path.join(scratch, name)
    run = subprocess.run([plume, "lab", "traction", path, "-o", out], capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError("plume lab traction %s failed (%d): %s" % (name, run.returncode, run.stderr.strip()))
    with open(os.path.join(out, "traction.json")) as f:
        return json.load(f)["slope_pa"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--plume", help="the plume binary (without it only the reference is checked)")
    parser.add_argument("--quick", action="store_true", help="one tilted reference mesh (no convergence check)")
    args = parser.parse_args()
    failures = []

    def check(name, value, reference, tolerance):
        error = abs(value / reference - 1.0)
        ok = error <= tolerance
        print("%-58s %14.8g vs %14.8g  rel. diff %.2e (tol %.0e) %s"
              % (name, value, reference, error, tolerance, "ok" if ok else "FAIL"))
        if not ok:
            failures.append(name)

    start = time.time()
    W, H = 10 * PERIOD, 13 * PERIOD  # whole periods: the barbs cover exactly Phi_B
    lon, cells, _, _ = traction(W, H, 0.0, 0.01, 10, h=PERIOD)
    check("reference longitudinal vs eq. 5.2 (%d cells)" % cells, lon, eq_5_2(), 1e-9)
    Ws = 10 * PERIOD
    tra, cells, strains, _ = traction(Ws, Ws, 0.5 * math.pi, 0.4, 10, h=PERIOD)
    rigid = fitted_slope(strains, [eq_5_4(e) for e in strains])
    check("reference transverse vs eq. 5.4 fitted (%d cells)" % cells, tra, rigid, 2e-4)
    check("reference transverse vs eq. 5.5", tra, eq_5_5(0.4), 2e-3)

    Wt, Ht = 4e-3, 5.2e-3
    # Element size along the barbs and rows across the barb and barbule bands.
    meshes = [(PERIOD / 6, 2, 4)] if args.quick else [(PERIOD / 6, 2, 4), (PERIOD / 9, 3, 6)]
    tilted = []
    for h, barb_rows, barbule_rows in meshes:
        t0 = time.time()
        slope, cells, _, _ = traction(Wt, Ht, 0.25 * math.pi, TILTED_STRAIN_MAX, 10, h, barb_rows, barbule_rows)
        print("reference tilted, eps_max %.2f, %6d P2 cells: slope %.8g Pa = %.6f E_b (%.1f s)"
              % (TILTED_STRAIN_MAX, cells, slope, slope / E_b, time.time() - t0))
        tilted.append(slope)
    if len(tilted) > 1:
        check("reference tilted: coarse mesh vs fine mesh", tilted[0], tilted[-1], 2e-3)
    reference_tilted = tilted[-1]

    if args.plume:
        with tempfile.TemporaryDirectory(prefix="plume-fenics-") as scratch:
            s = plume_slope(args.plume, scratch, "longitudinal", W, H, 0.0, 0.01, 10, 400)
            check("plume longitudinal vs reference", s, lon, 1e-4)
            s = plume_slope(args.plume, scratch, "transverse", Ws, Ws, 90.0, 0.4, 10, 400)
            check("plume transverse vs reference", s, tra, 1e-4)
            s = plume_slope(args.plume, scratch, "tilted", Wt, Ht, 45.0, TILTED_STRAIN_MAX, 10, 4000, 1e-8)
            check("plume tilted (4000 elements) vs reference", s, reference_tilted, TILTED_TOLERANCE)
            if not args.quick:
                s = plume_slope(args.plume, scratch, "tilted-fine", Wt, Ht, 45.0, TILTED_STRAIN_MAX, 10, 16000, 1e-8)
                check("plume tilted (16000 elements) vs reference", s, reference_tilted, TILTED_FINE_TOLERANCE)
    else:
        print("lab_fenics: no --plume: only the reference was checked")
    print("lab_fenics: %d failure(s), %.1f s" % (len(failures), time.time() - start))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

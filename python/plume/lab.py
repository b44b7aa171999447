"""The virtual lab (Jouve thesis chapters 3-5): traction tests, calibration, studies."""

from __future__ import annotations

import json
import math
import os
import tempfile
from typing import Any, Optional, Union

import numpy as np

from ._lib import Error, check, check_spec, ffi, fspath, lib, new_error


def _load_spec(spec: Union[dict, str, "os.PathLike[str]"]) -> Any:
    s = ffi.new("plume_lab_spec *")
    err = new_error()
    check_spec(spec, "lab.json", lambda path: lib.plume_lab_spec_load(path, s, err), err)
    return s


def traction(spec: Union[dict, str, "os.PathLike[str]"]) -> dict:
    """Runs the traction test of a lab file or dict (docs/lab.md: sample, material, traction).

    Returns strain, stress (Pa), displacement (m), iterations, converged, residual (arrays over
    the steps + 1 samples), slope (Pa), solve_count, newton_iterations, positions (N x 3, final)
    and lateral_strain."""
    s = _load_spec(spec)
    result = ffi.new("plume_traction_result *")
    err = new_error()
    check(lib.plume_lab_traction(ffi.addressof(s.material), ffi.addressof(s.sample), ffi.addressof(s.traction),
                                 result, err), err)
    try:
        n, nv = result.count, result.vertex_count

        def copy(p: Any, ctype: str, count: int, dtype: Any) -> np.ndarray:
            return np.frombuffer(ffi.buffer(p, count * ffi.sizeof(ctype)), dtype=dtype).copy()

        return {
            "strain": copy(result.strain, "double", n, np.float64),
            "stress": copy(result.stress, "double", n, np.float64),
            "displacement": copy(result.displacement, "double", n, np.float64),
            "iterations": copy(result.iterations, "int", n, np.intc),
            "converged": copy(result.converged, "bool", n, np.bool_),
            "residual": copy(result.residual, "double", n, np.float64),
            "slope": result.slope,
            "solve_count": result.solve_count,
            "newton_iterations": result.newton_iterations,
            "positions": copy(result.positions, "double", 3 * nv, np.float64).reshape(nv, 3),
            "lateral_strain": result.lateral_strain,
        }
    finally:
        lib.plume_traction_result_free(result)


def calibrate(*, barb_fraction: Optional[float] = None, E_B: Optional[float] = None, E_b: Optional[float] = None,
              period: Optional[float] = None, width: Optional[float] = None, thickness: Optional[float] = None,
              aspect_ratio: Optional[float] = None, steps: Optional[int] = None,
              barb_constraint: Optional[bool] = None, tolerance: Optional[float] = None,
              macroscale_elements: Optional[int] = None, phase_count: Optional[int] = None,
              element_count: Optional[int] = None, tilted_strain_max: Optional[float] = None,
              compression_coefficient: Optional[float] = None, macroscale_quadratic: Optional[bool] = None,
              uncertainty: Optional[bool] = None) -> dict:
    """Calibrates the macroscale moduli E_vv, E_ww, E_vw (Pa) from the mesoscale model (thesis 5.2-5.3).

    Keywords override plume_calibration_default_def(): barb_fraction is Phi_B, E_B and E_b the
    barb and barbule moduli (Pa), period the band period T (m), width/thickness the tilted sample's
    (m), element_count the mesoscale sample's target triangles, compression_coefficient Kikuuwe's
    kappa in both lab models (Pa, default 0: the protocol of docs/lab.md). Returns the result's
    fields, "protocol" (plume_calibration_protocol_name), "spread" (E_vv, E_ww, E_vw -> phase,
    width, mesh, total in Pa) and "curves": the four stress-strain curves matched, name ->
    (strain, stress Pa) arrays."""
    d = ffi.new("plume_calibration_def *", lib.plume_calibration_default_def())
    if barb_fraction is not None:
        d.mesoscale.bands.barb_fraction = barb_fraction
    if E_B is not None:
        d.mesoscale.E_B = E_B
    if E_b is not None:
        d.mesoscale.E_b = E_b
    if period is not None:
        d.mesoscale.bands.period = period
    if width is not None:
        d.sample.width = width
    if thickness is not None:
        d.sample.thickness = thickness
    if element_count is not None:
        d.sample.element_count = element_count
    if compression_coefficient is not None:
        d.mesoscale.compression_coefficient = compression_coefficient
    for name, value in (("aspect_ratio", aspect_ratio), ("steps", steps), ("barb_constraint", barb_constraint),
                        ("tolerance", tolerance), ("macroscale_elements", macroscale_elements),
                        ("phase_count", phase_count), ("tilted_strain_max", tilted_strain_max),
                        ("macroscale_quadratic", macroscale_quadratic), ("uncertainty", uncertainty)):
        if value is not None:
            setattr(d, name, value)
    d.keep_curves = True
    r = ffi.new("plume_calibration_result *")
    err = new_error()
    check(lib.plume_lab_calibrate(d, r, err), err)
    result = {name: getattr(r, name) for name in (
        "E_vv", "E_ww", "E_vw", "slope_longitudinal", "slope_transverse", "slope_tilted",
        "slope_tilted_macroscale", "sensitivity", "traction_count", "solve_count", "bisection_iterations")}
    result["protocol"] = ffi.string(lib.plume_calibration_protocol_name(d)).decode()
    result["spread"] = {name: {k: getattr(getattr(r, field), k) for k in ("phase", "width", "mesh", "total")}
                        for name, field in (("E_vv", "spread_vv"), ("E_ww", "spread_ww"), ("E_vw", "spread_vw"))}
    # The stress-strain curves matched (plume lab calibrate -o's curves.csv), copied out of the
    # result before it is freed: name -> (strain, stress in Pa).
    n = r.curve_samples
    result["curves"] = {
        name: (np.frombuffer(ffi.buffer(r.curve_strain[c], n * 8), dtype=np.float64).copy(),
               np.frombuffer(ffi.buffer(r.curve_stress[c], n * 8), dtype=np.float64).copy())
        for c, name in enumerate(("longitudinal", "transverse", "tilted_mesoscale", "tilted_macroscale"))}
    lib.plume_calibration_result_free(r)
    return result


def study(kind: str, *, scale: float = 1.0, csv: Optional[str] = None, png: Optional[str] = None,
          svg: Optional[str] = None) -> dict:
    """Runs a study ("locking", "conditioning", "angles", "size"; docs/lab.md), writing its table (CSV)
    and plot (PNG, SVG) where asked, and returns its JSON digest with the table's columns added
    under "table" (name -> array). scale multiplies every element count."""
    k = ffi.new("plume_study_kind *")
    if not lib.plume_study_kind_from_name(kind.encode(), k):
        raise ValueError(f"study {kind!r}; allowed: locking, conditioning, angles, size")
    d = ffi.new("plume_study_def *", lib.plume_study_default_def(k[0]))
    d.scale = scale
    summary = ffi.new("char[]", 4096)
    err = new_error()
    # The C study writes all three files; those not asked for go to a scratch folder.
    with tempfile.TemporaryDirectory(prefix="plume-study-") as folder:
        paths = [fspath(p, ext) if p is not None else os.path.join(folder, f"{kind}.{ext}")
                 for p, ext in ((csv, "csv"), (png, "png"), (svg, "svg"))]
        check(lib.plume_lab_study(d, *(os.fsencode(p) for p in paths), summary, 4096, err), err, files=paths)
        table = _read_csv(paths[0])
    text = ffi.string(summary).decode()
    result = json.loads(text) if text else {}
    result["table"] = table
    return result


def _read_csv(path: str) -> dict[str, np.ndarray]:
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(header)}


def mesoscale_moduli(barb_fraction: float, slope_longitudinal: float, slope_transverse: float,
                     transverse_strain_max: float = 0.4) -> tuple[float, float]:
    """(E_B, E_b), Pa: the mesoscale moduli that give the measured longitudinal and transverse slopes
    at barb fraction Phi_B (inverting thesis eqs. 5.3 and 5.5)."""
    E_B, E_b = ffi.new("double *"), ffi.new("double *")
    err = new_error()
    check(lib.plume_lab_mesoscale_moduli(barb_fraction, slope_longitudinal, slope_transverse, transverse_strain_max,
                                         E_B, E_b, err), err)
    return E_B[0], E_b[0]


def _check_closed_form(barb_fraction: float, **positive: float) -> None:
    """The ranges plume_lab_mesoscale_moduli checks (include/plume/lab.h): Phi_B in (0, 1), moduli
    and strains > 0. The closed forms themselves check nothing and answer garbage or NaN outside
    them (eq. 5.5 divides by (Phi_B - 1)^3), so the binding raises the same plume.Error here."""
    if not 0.0 < barb_fraction < 1.0:
        raise Error(f"barb fraction Phi_B is {barb_fraction:g}, allowed in (0, 1)")
    for name, value in positive.items():
        if not (value > 0.0 and math.isfinite(value)):
            raise Error(f"{name} is {value:g}, allowed finite and > 0")


def longitudinal_modulus(barb_fraction: float, E_B: float, E_b: float) -> float:
    """Phi_B E_B + (1 - Phi_B) E_b, Pa (thesis eq. 5.2). Phi_B in (0, 1), moduli > 0 (Pa), else plume.Error."""
    _check_closed_form(barb_fraction, E_B=E_B, E_b=E_b)
    return float(lib.plume_lab_longitudinal_modulus(barb_fraction, E_B, E_b))


def transverse_slope_rigid(barb_fraction: float, E_b: float, strain_max: float = 0.4) -> float:
    """Slope of the transverse test with rigid barbs over [0, strain_max], Pa (thesis eq. 5.5).
    Phi_B in (0, 1), E_b (Pa) and strain_max > 0, else plume.Error."""
    _check_closed_form(barb_fraction, E_b=E_b, strain_max=strain_max)
    return float(lib.plume_lab_transverse_slope_rigid(barb_fraction, E_b, strain_max))

"""Cross-key rules of a scene and the resolution of its ``auto`` defaults, on plain data.

:func:`resolve` takes a scene that passed the schema (defaults filled) and returns it complete:
run length rules checked, ``run.start``, ``run.output_interval``, ``run.transient`` and
``run.profile_bins``, ``run.max_density_error`` and its outliers, ``numerics.shifting``,
``numerics.shifting_rate`` and ``numerics.pressure_reference`` resolved, numbers as floats.
``run.dt``, ``run.sound_speed`` ("auto") and ``run.threads`` ("all") stay for the solver.
Problems go to ``fail(key_path, problem)``, which raises. Units as in :mod:`suspsim.scene`.
"""
from __future__ import annotations

import math
import re
from typing import Callable, NoReturn

from .rheology.laws import LAW_SPECS, ConstitutiveLaw, make_law

Fail = Callable[[tuple, str], NoReturn]

#: Smallest box side [h]: three cells of the neighbour list's cutoff h + skin (0.2 h,
#: ``sph.simulation.SKIN``), which also keeps every particle from meeting its own periodic image.
MIN_BOX_SIDE = 3.6
#: Largest relative gap between the initial lattice's density and number_density [choice].
LATTICE_DENSITY_TOLERANCE = 0.01
#: Automatic sampling of couette runs: every 0.05 strain, at least 20 samples [choice].
AUTO_OUTPUT_STRAIN = 0.05
AUTO_OUTPUT_MIN_SAMPLES = 20
#: Automatic sampling of poiseuille runs: 200 samples over the run [choice].
AUTO_OUTPUT_SAMPLES_POISEUILLE = 200
#: run.max_density_error auto: a fluid alone, and a fluid with bodies, whose gaps squeeze a few
#: fluid particles without a blow-up (measured, a = 2.5 h, 15 h box, strain 10: the largest
#: error 0.07 at φ = 0.1, 0.19 at 0.3, 0.23 at 0.4, on under 1 % of the particles) [choice].
AUTO_DENSITY_ERROR = 0.05
AUTO_DENSITY_ERROR_WITH_INCLUSIONS = 0.3
#: run.density_outlier_fraction auto with inclusions, and run.max_outlier_density_error auto
#: with inclusions as a multiple of run.max_density_error: one to three fluid particles caught
#: in gaps under 0.1 h between two bodies reach 0.25-0.37 and come and go, while the blow-up of
#: a dense run (φ = 0.4, 1.6 × the stable step) put 198 particles past 0.3 and one at 1.32 ten
#: steps before its NaN [choice].
AUTO_OUTLIER_FRACTION_WITH_INCLUSIONS = 1e-3
AUTO_OUTLIER_FACTOR_WITH_INCLUSIONS = 2.0


def resolve(scene: dict, given_run: dict, fail: Fail) -> tuple[dict, ConstitutiveLaw]:
    """Check the cross-key rules and return ``(complete scene, law)``.

    ``scene`` has passed the schema with defaults filled; ``given_run`` is the ``run`` mapping
    as the user wrote it (to tell an explicit ``start`` from the default).
    """
    out = {**scene, "dimension": int(scene["dimension"])}
    _check_box(out["dimension"], scene["box"], fail)
    law = _make_law(scene["fluid"], fail)
    out["fluid"] = {"law": law.name, "params": dict(law.params)}
    out["flow"] = _check_flow(scene["flow"], fail)
    out["run"] = _resolve_run(scene["run"], given_run, out["flow"], scene["box"], fail)
    _check_lattice(out["dimension"], scene["box"], scene["number_density"], fail)
    inclusions = _has_inclusions(scene["inclusions"])
    out["numerics"] = _resolve_numerics(scene["numerics"], inclusions, out["flow"],
                                        law.is_newtonian, fail)
    out["inclusions"] = _resolve_cutoff(scene["inclusions"], out["numerics"])
    _check_inclusions(out, fail)
    _resolve_density_limits(out["run"], inclusions, fail)
    return out, law


def _resolve_density_limits(run: dict, inclusions: bool, fail: Fail) -> None:
    """Fill the auto density limits of ``run`` in place (:data:`AUTO_DENSITY_ERROR` and the
    outlier constants above) and refuse an outlier ceiling below the bulk limit."""
    if run["max_density_error"] == "auto":
        run["max_density_error"] = (AUTO_DENSITY_ERROR_WITH_INCLUSIONS if inclusions
                                    else AUTO_DENSITY_ERROR)
    if run["density_outlier_fraction"] == "auto":
        run["density_outlier_fraction"] = (AUTO_OUTLIER_FRACTION_WITH_INCLUSIONS if inclusions
                                           else 0.0)
    if run["max_outlier_density_error"] == "auto":
        factor = AUTO_OUTLIER_FACTOR_WITH_INCLUSIONS if inclusions else 1.0
        run["max_outlier_density_error"] = factor * run["max_density_error"]
    if run["max_outlier_density_error"] < run["max_density_error"]:
        fail(("run", "max_outlier_density_error"),
             f"{run['max_outlier_density_error']:g} is below run.max_density_error "
             f"{run['max_density_error']:g}: the outliers' ceiling must be at least the limit "
             "the other particles keep")


def lattice_counts(box, number_density: float) -> tuple[int, ...]:
    """Sites per side of the simple cubic/square lattice at ``number_density`` [h^-d] in ``box`` [h]."""
    spacing = number_density ** (-1.0 / len(box))
    return tuple(max(1, round(side / spacing)) for side in box)


def _check_box(dim: int, box, fail: Fail) -> None:
    if len(box) != dim:
        fail(("box",), f"a {dim}-D scene needs {dim} box lengths "
                       f"({'x, y, z' if dim == 3 else 'x, y'}), got {len(box)}")
    for i, side in enumerate(box):
        if side < MIN_BOX_SIDE:
            fail(("box", i), f"box side {side:g} h is below {MIN_BOX_SIDE:g} h, three cells "
                             f"of the neighbour list (h + skin); make it at least "
                             f"{MIN_BOX_SIDE:g}")


def _make_law(fluid: dict, fail: Fail) -> ConstitutiveLaw:
    name, params = fluid["law"], fluid["params"]
    if name not in LAW_SPECS:
        fail(("fluid", "law"), f"unknown law {name!r}; known laws: {', '.join(LAW_SPECS)}")
    try:
        return make_law(name, params)
    except ValueError as err:
        named = re.match(r"\w+: (?:parameter )?(\w+)\b", str(err))
        which = (named.group(1),) if named and named.group(1) in params else ()
        fail(("fluid", "params", *which), str(err))


#: Shifting coefficient A of numerics.shifting auto in a scene with inclusions [choice]: one
#: sphere then carries its Einstein stresslet and the fluid around it its viscosity, and the
#: two-sphere squeeze force follows theory down to the lubrication cutoff (the schema's
#: description gives the measurements).
AUTO_SHIFTING_WITH_INCLUSIONS = 30.0
#: The same in a non-Newtonian matrix [choice]: shifting stirs the fluid, and a shear-thinning
#: law reads the stir as rate (``terms.shifting``); A = 3 keeps the Newtonian η_r of A = 30 with
#: a quarter of the stir. Its cost: the resolved two-sphere squeeze force reads 0.72–0.80 of
#: Jeffrey–Onishi at 0.6–3.3 h (a = 2.5 h, Re = 0.05; a_h/a = 0.92 from the drag), so the
#: lubrication cutoff calibrated at A = 30 under-corrects there.
AUTO_SHIFTING_NON_NEWTONIAN = 3.0


#: Lubrication cutoff s_c [h] of inclusions.lubrication.cutoff_gap auto with
#: numerics.spin_correction, by shifting coefficient A [choice]: the largest gap at which the
#: resolved two-sphere force falls below 0.9 of Jeffrey–Onishi (``validation.squeeze.cutoff_gap``
#: on the mean over four lattice phases; a = 2.5 h, Re = 0.05, docs/figures/make_squeeze.py
#: --no-large --phases 4 [--slide 1] --set numerics.shifting=A), the largest of three readings:
#: the squeeze in a pure approach (0.438, 0.185 and 0.138 h at A = 3, 30 and 100), the squeeze
#: while sliding at the same speed (``--slide 1``, a pair at 45° in a shear's compressional
#: quadrant: 0.437, 0.104 and 0.185 h) and the sliding force beside it (never short, 0.185 h,
#: never short). A sheared pair both approaches and slides, and the correction must cover every
#: gap where a motion's resolved force falls short. Other A interpolate in log A and hold the
#: end values beyond. One phase alone misleads: at A = 30 a single phase's sliding force reads
#: 0.11–1.44 × theory below 0.25 h (docs/suspensions.md, "Lattice phases").
AUTO_CUTOFF_GAP_CORRECTED = ((3.0, 0.44), (30.0, 0.185), (100.0, 0.185))
#: The same with shifting tangential at the bodies (numerics.shifting_at_bodies; the same
#: commands with --no-half-speed --set numerics.shifting_at_bodies='"tangential"'), over four
#: phases: approach 0.328, 0.246 and 0.185 h at A = 3, 30 and 100, the squeeze while sliding
#: 0.583, 0.246 and 0.185 h, the sliding force never short. At A = 3 the sliding squeeze's
#: shortfall (0.75–0.87 × at 0.14–0.58 h) is partly the sphere's smaller hydrodynamic radius
#: (a_h/a = 0.962; against a_h's theory it reads ≥ 1.09), but the rule reads the nominal theory
#: at every A. The shortfall taken is the one that reaches down to contact: the approach's bin
#: at 2.46 h reads 0.88 at A = 3 (phases 0.72–1.26), the end of its spin-up stretch.
AUTO_CUTOFF_GAP_TANGENTIAL = ((3.0, 0.583), (30.0, 0.246), (100.0, 0.185))
#: The same without the spin correction (A = 30, numerics.spin_correction=false), over four
#: phases: approach 0.583 h, the squeeze while sliding 0.778 h (0.85–0.88 × at 0.33–0.78 h,
#: 0.97 at 1.04 h), the sliding force 0.328 h; one phase had read 0.6 and 0.778 h.
AUTO_CUTOFF_GAP_UNCORRECTED = 0.778


def _resolve_cutoff(inclusions: dict, numerics: dict) -> dict:
    """``inclusions.lubrication.cutoff_gap`` auto → :data:`AUTO_CUTOFF_GAP_CORRECTED` (or
    :data:`AUTO_CUTOFF_GAP_TANGENTIAL` with shifting tangential at the bodies) at the scene's
    shifting coefficient with the spin correction, else :data:`AUTO_CUTOFF_GAP_UNCORRECTED`."""
    lub = dict(inclusions["lubrication"])
    if lub["cutoff_gap"] == "auto":
        lub["cutoff_gap"] = AUTO_CUTOFF_GAP_UNCORRECTED
        if numerics["spin_correction"]:
            table = (AUTO_CUTOFF_GAP_TANGENTIAL if numerics["shifting_at_bodies"] == "tangential"
                     else AUTO_CUTOFF_GAP_CORRECTED)
            lub["cutoff_gap"] = _log_interpolate(table, numerics["shifting"])
    lub["cutoff_gap"] = float(lub["cutoff_gap"])
    return {**inclusions, "lubrication": lub}


def _log_interpolate(points, x: float) -> float:
    """y(x) piecewise linear in (log x, log y) through ``points`` ((x, y), x increasing), held at
    the end values beyond them."""
    (x0, y0), (xn, yn) = points[0], points[-1]
    if x <= x0:
        return y0
    if x >= xn:
        return yn
    for (xa, ya), (xb, yb) in zip(points, points[1:]):
        if x <= xb:
            t = math.log(x / xa) / math.log(xb / xa)
            return math.exp((1 - t) * math.log(ya) + t * math.log(yb))


def _resolve_numerics(numerics: dict, inclusions_present: bool, flow: dict, newtonian: bool,
                      fail: Fail) -> dict:
    """``spin_correction`` auto → on with inclusions, off without (a fluid alone has nothing
    its angular momentum couples to, and the correction costs accuracy at kinks of the rate,
    ``terms.viscous.local_spin``); ``shifting`` auto → :data:`AUTO_SHIFTING_WITH_INCLUSIONS`
    with inclusions (:data:`AUTO_SHIFTING_NON_NEWTONIAN` in a non-Newtonian matrix), 0 without;
    ``shifting_rate`` auto → the imposed shear rate of a couette flow, 0 otherwise (shifting's
    diffusivity is A h² γ_s δt, ``terms.shifting``); ``shifting_at_bodies`` auto → full
    (``terms.shifting``: tangential is the option that strong shifting needs);
    ``rate_smoothing`` auto → on where shifting acts on a non-Newtonian fluid
    (``terms.rate_smoothing``); ``pressure_reference`` auto → fluid_mean where shifting acts
    (A > 0 and γ_s > 0), nominal elsewhere; an explicit fluid_mean where it does not is refused
    (particles pair up, SPEC §2.3)."""
    out = dict(numerics)
    if numerics["spin_correction"] == "auto":
        out["spin_correction"] = inclusions_present
    out["spin_correction"] = bool(out["spin_correction"])
    if numerics["shifting"] == "auto":
        with_inclusions = (AUTO_SHIFTING_WITH_INCLUSIONS if newtonian
                           else AUTO_SHIFTING_NON_NEWTONIAN)
        out["shifting"] = with_inclusions if inclusions_present else 0.0
    out["shifting"] = float(out["shifting"])
    if numerics["shifting_rate"] == "auto":
        out["shifting_rate"] = float(flow["shear_rate"]) if flow["type"] == "couette" else 0.0
    out["shifting_rate"] = float(out["shifting_rate"])
    if numerics["shifting_at_bodies"] == "auto":
        out["shifting_at_bodies"] = "full"
    reference = numerics["pressure_reference"]
    shifting = out["shifting"] > 0.0 and out["shifting_rate"] > 0.0
    if numerics["rate_smoothing"] == "auto":
        out["rate_smoothing"] = shifting and not newtonian
    out["rate_smoothing"] = bool(out["rate_smoothing"])
    if reference == "auto":
        out["pressure_reference"] = "fluid_mean" if shifting else "nominal"
    elif reference == "fluid_mean" and not shifting:
        fail(("numerics", "pressure_reference"), "fluid_mean needs numerics.shifting > 0 and "
             "a shifting rate (with a zero mean pressure nothing else keeps the particles from "
             "pairing up); set shifting, e.g. 30, and in a flow without an imposed shear rate "
             "numerics.shifting_rate, or use nominal")
    return out


def _check_flow(flow: dict, fail: Fail) -> dict:
    kind, rate, force = flow["type"], float(flow["shear_rate"]), float(flow["body_force"])
    if kind == "couette":
        if rate <= 0:
            fail(("flow", "shear_rate"), "couette flow needs shear_rate > 0 [1/tau]")
        if force != 0:
            fail(("flow", "body_force"), "couette flow takes no body force; remove it or set 0")
    else:
        if force <= 0:
            fail(("flow", "body_force"), "poiseuille flow needs body_force > 0 [h/tau^2]")
        if rate != 0:
            fail(("flow", "shear_rate"), "poiseuille flow has no imposed shear rate; remove it or set 0")
    return {"type": kind, "shear_rate": rate, "body_force": force}


def _resolve_run(run: dict, given: dict, flow: dict, box, fail: Fail) -> dict:
    if "strain" in run and "time" in run:
        fail(("run", "time"), "give either run.strain or run.time, not both")
    if "strain" not in run and "time" not in run:
        fail(("run", "strain"), "missing the run length: give run.strain (couette) or run.time")
    couette = flow["type"] == "couette"
    if not couette and "strain" in run:
        fail(("run", "strain"), "poiseuille flow has no imposed strain; give run.time instead")
    if not couette and given.get("start", "rest") != "rest":
        fail(("run", "start"), "poiseuille flow starts from rest; remove run.start or set it to rest")
    length_key = "strain" if "strain" in run else "time"
    length = float(run[length_key])
    interval = run["output_interval"]
    if interval == "auto" and couette:
        per_strain = 1.0 if length_key == "strain" else 1.0 / flow["shear_rate"]
        interval = min(AUTO_OUTPUT_STRAIN * per_strain, length / AUTO_OUTPUT_MIN_SAMPLES)
    elif interval == "auto":
        interval = length / AUTO_OUTPUT_SAMPLES_POISEUILLE
    elif interval > length:
        fail(("run", "output_interval"), f"output_interval {interval:g} exceeds the run "
                                         f"{length_key} {length:g}")
    transient = length / 2 if run["transient"] == "auto" else run["transient"]
    if transient >= length:
        fail(("run", "transient"), f"transient {transient:g} leaves nothing of the run "
                                   f"{length_key} {length:g} to average")
    out = {key: (float(v) if isinstance(v, (int, float)) else v) for key, v in run.items()}
    out.update({length_key: length, "start": run["start"] if couette else "rest",
                "output_interval": float(interval), "transient": float(transient),
                "profile_bins": (max(1, int(box[1])) if run["profile_bins"] == "auto"
                                 else int(run["profile_bins"]))})
    if run["threads"] != "all":
        out["threads"] = int(run["threads"])
    return out


def lattice_mismatch(dim: int, box, n: float) -> str | None:
    """Why a ``dim``-D box of sides ``box`` [h] holds no whole lattice at ``n`` particles per
    h^dim (more than LATTICE_DENSITY_TOLERANCE off, with box sides that would fit), or None."""
    counts = lattice_counts(box, n)
    actual = math.prod(counts) / math.prod(box)
    if abs(actual / n - 1) <= LATTICE_DENSITY_TOLERANCE:
        return None
    spacing = n ** (-1.0 / dim)
    fitting = ", ".join(f"{c * spacing:.4g}" for c in counts)
    return (f"a {'x'.join(map(str, counts))} lattice gives {actual:.4g} particles per h^{dim} "
            f"in this box, {100 * (actual / n - 1):+.1f} % off number_density {n:g}; use box "
            f"sides that are multiples of the spacing {spacing:.4g} h, e.g. [{fitting}]")


def _check_lattice(dim: int, box, n: float, fail: Fail) -> None:
    problem = lattice_mismatch(dim, box, n)
    if problem:
        fail(("number_density",), problem)


def _has_inclusions(inc: dict) -> bool:
    return inc["phi"] > 0 or inc["packing"] is not None


def _check_inclusions(scene: dict, fail: Fail) -> None:
    inc = scene["inclusions"]
    if not _has_inclusions(inc):
        return
    if scene["dimension"] != 3:
        fail(("inclusions",), "rigid inclusions need a 3-D scene")
    if scene["flow"]["type"] != "couette":
        fail(("inclusions",), "rigid inclusions run in couette flow only (the suspension "
                              "viscosity); use flow.type: couette")
    lub = inc["lubrication"]
    if lub["enabled"] and not lub["min_gap"] < lub["cutoff_gap"]:
        fail(("inclusions", "lubrication", "min_gap"),
             f"min_gap {lub['min_gap']:g} must be below cutoff_gap {lub['cutoff_gap']:g}")

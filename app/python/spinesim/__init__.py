"""spinesim from Python: mesh a disc, solve its FEM reference, build, step and calibrate its
mass-spring model, solve the spine standing and seated, and run study files.

Units everywhere: mm, N, N·mm, MPa, seconds, degrees for motions given here (radians nowhere).
Frame: x lateral (the body's right is -x), y superior, z anterior.

    import spinesim
    disc = spinesim.mesh_disc(level="L4-L5")                   # a Mesh (NumPy views)
    r = spinesim.fem(disc, case="flexion")                     # the linear FEM reference
    r.reaction_wrench, r.fields["von_mises_MPa"]               # NumPy arrays
    mss = spinesim.MassSpringDisc(disc)                        # untuned Van Gelder constants
    s = mss.solve(case="flexion")                              # static equilibrium
    sim = mss.simulation(dt_s=1e-3); sim.step(motion_deg=[0, -0.2, 0, 0, 0, 0], steps=100)
    spinesim.spine(forces={"T7": [0, 0, 300]}).joints          # the standing spine
    spinesim.run_study("examples/disc-stress/study.json")      # a study file, its JSON summary

Results are `Result`s: dictionaries whose keys are also attributes. Refused input raises
ValueError with one line; work that ran and failed (no convergence) raises RuntimeError.
"""
import json as _json
import os as _os
import sys as _sys

from . import _spinesim

try:
    import numpy as _numpy  # noqa: F401  (the arrays the module returns)
except ImportError:
    # Another CPython of the version the module was built for (a pyenv one first on PATH) without
    # NumPy of its own: Debian's python3-numpy, which scripts/install-deps.sh installs, serves it.
    _debian = "/usr/lib/python3/dist-packages"
    if (tuple(_sys.version_info[:2]) == tuple(_spinesim.built_for_python)
            and _os.path.isdir(_os.path.join(_debian, "numpy"))):
        _sys.path.append(_debian)
from ._spinesim import (Mesh, MassSpringDisc, Simulation, data_dir, import_artisynth,
                        load_cases, main, named_bodies, read_mesh, seating_parameters)

__all__ = ["Mesh", "MassSpringDisc", "Simulation", "Result", "mesh_disc", "read_mesh",
           "import_artisynth", "fem",
           "export_abaqus", "export_febio", "calibrate", "spine", "seated_spine", "run_study", "main",
           "load_cases", "seating_parameters", "named_bodies", "data_dir"]

# What the script writes names the script (its provenance: program, commit, command, inputs).
_spinesim._record_script([_os.path.basename(_sys.executable) or "python3"] +
                         (list(_sys.argv) if getattr(_sys, "argv", None) else []))


class Result(dict):
    """A dictionary whose keys are also attributes (r.fields, r["fields"])."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no '{name}' in this result (it has: {', '.join(self)})") from None

    def __dir__(self):
        return list(self) + list(super().__dir__())


def _result(d):
    if isinstance(d, dict):
        return Result({k: _result(v) for k, v in d.items()})
    return d


def _numbers(v, n, what):
    """`v` as n floats (None stays None); ValueError naming `what` otherwise."""
    if v is None:
        return None
    values = [float(x) for x in v]
    if len(values) != n:
        raise ValueError(f"{what}: give {n} numbers, not {len(values)}")
    return values


def _six(v, what):
    return _numbers(v, 6, what)


def _three(v, what):
    return _numbers(v, 3, what)


def mesh_disc(level="", *, inferior="", superior="", surface_mm_per_unit=1.0, up="y",
              structured=False, sectors=12, rings=3, layers=2, cell_size_mm=2.0, seed=0, out=""):
    """A disc mesh: a parametric level ("T1-T2" … "L5-S1"), or the disc between two vertebra
    (or endplate) surface files (STL, OBJ, PLY, OFF, VTU/VTK surfaces) in `surface_mm_per_unit`
    with `up` their superior axis. CGAL Mesh_3 with `cell_size_mm`, or (`structured`) the
    structured sweep of `sectors` × `rings` × `layers` (the haptic disc: fast, coarse).
    Writes `out` (VTU) when given. The Mesh's `info` holds its quality and what it was made from.
    """
    return _spinesim.mesh_disc(level=level, inferior=inferior, superior=superior,
                               surface_mm_per_unit=surface_mm_per_unit, up=up,
                               structured=structured, sectors=sectors, rings=rings,
                               layers=layers, cell_size_mm=cell_size_mm, seed=seed, out=out)


def fem(mesh, *, material="real-disc", case="", motion_deg=None, wrench=None, center=None,
        order=2, formulation="displacement", nonlinear=False, increments=10, out=""):
    """The linear FEM reference: the inferior endplate fixed, the superior one a rigid plate
    under one load — a named `case` (load_cases()), a `motion_deg` (tx, ty, tz mm; rx, ry, rz
    deg) or a `wrench` (Fx, Fy, Fz N; Mx, My, Mz N·mm), about `center` (mm; default the plate's
    centre). `order` 1 or 2; `formulation` "displacement" or "mixed" (Taylor–Hood, order 2).

    Returns a Result: displacement_mm (N, 3), plate_motion_deg (6), reaction_wrench (6, N and
    N·mm, what the disc exerts on the plate), stiffness_per_deg (6×6), point_data and fields
    (per-tet arrays named as in the VTU, units in the names: stress_MPa (M, 6: xx yy zz xy yz
    xz), von_mises_MPa, pressure_MPa, strain, principal_strain, fibre_stretch, ...) and the
    summary the program prints with --json. Writes `out` (VTU) when given.

    `nonlinear`: the nonlinear disc (finite strain, tension-only fibres, nearly incompressible
    nucleus) in `increments` load steps; its fields: cauchy_stress_MPa, von_mises_MPa,
    pressure_MPa, green_lagrange_strain, principal_stretch, principal_stretch_direction_1..3,
    fibre_stretch, fibre_stress_MPa, volume_ratio, strain_energy_density_MPa (no
    stiffness_per_deg or point_data).
    """
    if nonlinear:
        if formulation != "displacement":
            raise ValueError("nonlinear: the nonlinear disc takes its own volumetric form; "
                             "leave out formulation")
        return _result(_spinesim._fem_nonlinear(mesh, material, case,
                                                _six(motion_deg, "motion_deg"),
                                                _six(wrench, "wrench"), _three(center, "center"),
                                                int(order), int(increments), out))
    return _result(_spinesim._fem(mesh, material, case, _six(motion_deg, "motion_deg"),
                                  _six(wrench, "wrench"), _three(center, "center"), int(order),
                                  formulation, out))


def export_abaqus(path, mesh, *, material="real-disc", case="", motion_deg=None, wrench=None,
                  center=None, order=2):
    """Writes the FEM problem fem() would solve as an Abaqus/CalculiX deck (.inp) at `path`:
    `ccx` runs it as it is. Returns the element type (C3D4 or C3D10)."""
    return _spinesim._export_abaqus(path, mesh, material, case, _six(motion_deg, "motion_deg"),
                                    _six(wrench, "wrench"), _three(center, "center"), int(order))


def export_febio(path, mesh, *, material="real-disc", case="", motion_deg=None, wrench=None,
                 center=None, order=2):
    """Writes the FEM problem fem() would solve as an FEBio file (.feb, spec 4.0) at `path`:
    tet4/tet10, each fibre tet an orthotropic material in its fibre axes, the plate motion
    prescribed on the superior endplate. A `case` or `wrench` is written as the plate motion
    fem() finds under it (FEBio needs a rigid part for a wrench). Returns a Result: element,
    plate_motion_deg, plate_center_mm."""
    return _result(_spinesim._export_febio(path, mesh, material, case,
                                           _six(motion_deg, "motion_deg"), _six(wrench, "wrench"),
                                           _three(center, "center"), int(order)))


def _solve(self, *, case="", motion_deg=None, wrench=None, center=None):
    """Static equilibrium of the mass-spring disc under one plate load (as fem()). Returns a
    Result: positions_mm and displacement_mm (N, 3), plate_motion_deg, reaction_wrench, fields
    (green_lagrange_strain, edge_spring_force_N, volume_change per tet) and the summary.
    Raises RuntimeError when Newton does not converge."""
    return _result(self._solve(case, _six(motion_deg, "motion_deg"), _six(wrench, "wrench"),
                               _three(center, "center")))


def _step(self, *, case="", motion_deg=None, wrench=None, center=None, steps=1):
    """Advances `steps` time steps with the plate held at `motion_deg` (mm, deg) or loaded by
    `wrench` or a named `case` (none: the plate back at rest). Move the plate gradually: a jump
    of the pose in one step gives the endplate nodes a velocity of jump/dt. Raises RuntimeError
    on a rejected (diverging) step, the state left as it was before that step."""
    self._step(case, _six(motion_deg, "motion_deg"), _six(wrench, "wrench"),
               _three(center, "center"), int(steps))


MassSpringDisc.solve = _solve
Simulation.step = _step


def calibrate(mesh, *, material="real-disc", train=("compression", "shear-ap", "flexion", "torsion"),
              holdout=None, terms="thesis+volume", order=2, check=True, out=""):
    """Tunes the mass-spring disc's per-region constants to the FEM of `mesh` (Ipopt) on the
    `train` cases; `holdout` (default: every other case) are checked, not fitted. `terms`:
    "thesis", "thesis+volume" or "all". `check` also runs the nonlinear MSS against the FEM on
    every case. Writes the tuned file `out` (for MassSpringDisc(params=...)) when it succeeded.
    Returns a Result: success, status, iterations, seconds, tuned (the file's content),
    untuned_check and tuned_check (per case errors), out."""
    train = [train] if isinstance(train, str) else list(train)
    if holdout is None:
        holdout = [c for c in load_cases() if c not in train]
    holdout = [holdout] if isinstance(holdout, str) else list(holdout)
    return _result(_spinesim._calibrate(mesh, material, train, holdout, terms, int(order),
                                        bool(check), out))


def _body(subject, height_m, body_mass_kg, sex):
    """(height_m, body_mass_kg, sex) of the named body `subject`, or the given ones."""
    if not subject:
        return float(height_m), float(body_mass_kg), sex
    if height_m or body_mass_kg or sex != "male":
        raise ValueError("subject names a whole body: give it without height_m, body_mass_kg "
                         "or sex")
    b = _spinesim._named_body(subject)
    return b["height_m"], b["body_mass_kg"], b["sex"]


def spine(*, forces=None, moments=None, fusion="", muscles=True, trunk_muscles=True,
          gravity=True, disc_joints="", ligaments="auto", height_m=0.0, body_mass_kg=0.0,
          sex="male", subject="", rib_cage=False, scoliosis=None, muscle_strength=1.0,
          joint_stiffness=1.0, ligament_stiffness=1.0, inclination_deg=0.0):
    """The standing thoracolumbar spine's equilibrium under gravity and dead loads: `forces`
    {"T7": [Fx, Fy, Fz]} in N at the vertebra's centre, `moments` {"L1": [Mx, My, Mz]} in N·mm;
    `fusion` such as "L3-L4-L5"; `disc_joints` a preset or file of disc joint stiffnesses;
    `ligaments` "auto" (only on disc joints: the thesis's F.4 springs include them), "on" or "off";
    the body `height_m`, `body_mass_kg`, `sex` ("male"/"female"; zeros: the reference 1.778 m,
    70 kg male) scales the spine (a height or body-mass index out of range raises ValueError),
    or `subject` names a sourced body instead (named_bodies(): "p5-female", "reference",
    "p95-male");
    `rib_cage` adds the ribs and sternum on the thoracic vertebrae (off: the thesis's spine);
    `scoliosis` a dict {"type": "thoracic"|"thoracolumbar"|"lumbar", "cobb_deg": 40, optional
    "apex", "curve_ends": ("T6", "T12"), "apical_rotation_deg", "convex": "right"|"left"} makes
    the spine rest in that curve (spine/README.md; a curve it cannot pose raises ValueError).
    The uncertain inputs, for sensitivity studies (spine/README.md; 0.1-10 and -30-90 deg, else
    ValueError): `muscle_strength`, `joint_stiffness` and `ligament_stiffness` multiply every
    muscle's maximum stress, joint's rotational stiffness and ligament's stiffness;
    `inclination_deg` pitches the standing body forward (gravity turns in the pelvis's frame).
    Returns the Result `spinesim spine solve --json` prints (vertebrae, joints, muscles,
    ligaments, bushing, warnings, units). Raises RuntimeError when it does not converge."""
    height_m, body_mass_kg, sex = _body(subject, height_m, body_mass_kg, sex)
    return _result(_spinesim._spine(dict(forces or {}), dict(moments or {}), fusion, muscles,
                                    trunk_muscles, gravity, disc_joints, ligaments,
                                    height_m, body_mass_kg, sex, bool(rib_cage),
                                    dict(scoliosis or {}),
                                    [float(muscle_strength), float(joint_stiffness),
                                     float(ligament_stiffness), float(inclination_deg)]))


def seated_spine(*, armrests=False, chair_surface="", fusion="", disc_joints="", ligaments="auto",
                 height_m=0.0, body_mass_kg=0.0, sex="male", subject="", rib_cage=False,
                 scoliosis=None, **chair):
    """The spine seated on a chair: keyword arguments from seating_parameters() (e.g.
    backrest_recline=110 (deg), lumbar_support=20 (mm), seat_angle, backrest_height,
    pelvic_tilt; hyphens or underscores), `armrests`, a backrest surface file `chair_surface`,
    `ligaments`, `height_m`, `body_mass_kg`, `sex`, `subject`, `rib_cage` and `scoliosis` as in
    spine().
    Returns the Result `spinesim study seating --json` prints."""
    known = seating_parameters()
    values = {}
    for key, value in chair.items():
        name = key.replace("_", "-")
        if name not in known:
            raise ValueError(f"seated_spine: unknown chair parameter '{key}' "
                             f"(use {', '.join(k.replace('-', '_') for k in known)})")
        values[name] = float(value)
    height_m, body_mass_kg, sex = _body(subject, height_m, body_mass_kg, sex)
    return _result(_spinesim._seated_spine(values, armrests, chair_surface, fusion, disc_joints,
                                           ligaments, height_m, body_mass_kg, sex,
                                           bool(rib_cage), dict(scoliosis or {})))


def run_study(path, *extra):
    """Runs a study file (a verb and its options as JSON; `spinesim run --schema`) in its
    folder, in this process, and returns its JSON summary as a Result. `extra` options are added
    to the study's (as `spinesim run STUDY ...`). Raises ValueError naming the field of a wrong
    study, RuntimeError when the work failed."""
    text = _spinesim._execute(["run", _os.fspath(path), *extra, "--json", "--quiet"])
    return _result(_json.loads(text)) if text.strip() else Result()

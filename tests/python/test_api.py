"""The Python module against the program it shares its drivers with, and against properties
(linearity, equilibrium, the stress invariants recomputed in NumPy)."""
import json
import math

import numpy as np
import pytest

import spinesim
from conftest import assert_json_close


def test_mesh_arrays_and_round_trip(tmp_path):
    m = spinesim.mesh_disc("L4-L5", structured=True)
    assert m.nodes.shape == (m.num_nodes, 3) and m.tets.shape == (m.num_tets, 4)
    assert set(np.unique(m.region)) == {1, 2}
    assert {1, 2} <= set(np.unique(m.surface))
    # Positively oriented tets: the volume is the sum of det/6, recomputed here.
    a, b, c, d = (m.nodes[m.tets[:, i]] for i in range(4))
    dets = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)
    assert (dets > 0).all()
    assert math.isclose(dets.sum() / 6, m.volume_mm3, rel_tol=1e-12)
    assert math.isclose(m.info["volume_mm3"], m.volume_mm3, rel_tol=1e-9)
    assert m.info["tets"] == m.num_tets and m.info["out"] is None
    path = tmp_path / "m.vtu"
    m.write(str(path))
    back = spinesim.read_mesh(str(path))
    np.testing.assert_array_equal(back.tets, m.tets)
    np.testing.assert_array_equal(back.region, m.region)
    np.testing.assert_array_equal(back.nodes, m.nodes)
    np.testing.assert_allclose(back.frame_axes, m.frame_axes)


def test_mesh_views_write_through():
    m = spinesim.mesh_disc("L4-L5", structured=True)
    v0 = m.volume_mm3
    m.nodes[:, 1] *= 2.0  # the arrays are views: doubling the heights doubles the volume
    assert math.isclose(m.volume_mm3, 2 * v0, rel_tol=1e-12)


def test_bad_input_is_a_value_error():
    with pytest.raises(ValueError, match="L9-L10|level"):
        spinesim.mesh_disc("L9-L10", structured=True)
    with pytest.raises(ValueError, match="motion_deg"):
        spinesim.fem(spinesim.mesh_disc("L4-L5", structured=True), motion_deg=[1, 2])
    with pytest.raises(ValueError, match="case"):
        spinesim.fem(spinesim.mesh_disc("L4-L5", structured=True), case="somersault")


def test_fem_equals_the_program(disc, disc_file, program):
    r = spinesim.fem(disc, case="flexion", order=2)
    p = program("fem", "--mesh", disc_file, "--case", "flexion", "--order", 2)
    np.testing.assert_allclose(r.summary["reaction_wrench"], p["reaction_wrench"], rtol=1e-12,
                               atol=1e-9)
    np.testing.assert_allclose(r.reaction_wrench, p["reaction_wrench"], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(r.plate_motion_deg, p["plate_motion"], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(r.stiffness_per_deg, p["stiffness_6x6"], rtol=1e-12)


def test_fem_is_linear_and_its_stiffness_maps_motion_to_reaction(disc):
    motion = np.array([0.01, -0.05, 0.02, 0.3, 0.1, -0.2])  # mm, deg
    r1 = spinesim.fem(disc, motion_deg=motion, order=1)
    r2 = spinesim.fem(disc, motion_deg=2 * motion, order=1)
    np.testing.assert_allclose(r2.displacement_mm, 2 * r1.displacement_mm, rtol=1e-9, atol=1e-12)
    # The stiffness gives the load that holds the plate there: minus the disc's reaction on it.
    np.testing.assert_allclose(r1.stiffness_per_deg @ motion, -r1.reaction_wrench, rtol=1e-8,
                               atol=1e-8 * np.abs(r1.reaction_wrench).max())
    # The plate takes the prescribed motion; the fixed endplate does not move.
    np.testing.assert_allclose(r1.plate_motion_deg, motion, atol=1e-12)
    assert np.abs(r1.displacement_mm[disc.surface == 1]).max() == 0.0


def test_fem_fields_satisfy_their_definitions(disc):
    r = spinesim.fem(disc, case="compression", material="fibre-reinforced")
    s = r.fields["stress_MPa"]  # xx yy zz xy yz xz
    assert s.shape == (disc.num_tets, 6)
    vm = np.sqrt(0.5 * ((s[:, 0] - s[:, 1]) ** 2 + (s[:, 1] - s[:, 2]) ** 2 +
                        (s[:, 2] - s[:, 0]) ** 2) + 3 * (s[:, 3] ** 2 + s[:, 4] ** 2 + s[:, 5] ** 2))
    np.testing.assert_allclose(r.fields["von_mises_MPa"], vm, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(r.fields["pressure_MPa"], -s[:, :3].sum(axis=1) / 3, rtol=1e-10,
                               atol=1e-14)
    assert r.fields["fibre_stretch"].shape == (disc.num_tets, 2)
    assert set(r.point_data) >= {"displacement"}


def test_strain_energy_is_the_work_of_the_plate(disc):
    # Linear P1 (constant strain per tet): the sum of energy density × volume is the stored
    # energy, which equals the work done on the plate, -1/2 reaction · motion (theta in rad).
    motion = np.array([0.02, -0.05, 0.01, 0.3, -0.2, 0.1])  # mm, deg
    r = spinesim.fem(disc, motion_deg=motion, order=1, material="fibre-reinforced")
    a, b, c, d = (disc.nodes[disc.tets[:, i]] for i in range(4))
    vol = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) / 6
    energy = (r.fields["strain_energy_density_MPa"] * vol).sum()
    work = -0.5 * r.reaction_wrench @ np.concatenate([motion[:3], np.radians(motion[3:])])
    assert energy > 0
    assert math.isclose(energy, work, rel_tol=1e-8)


def test_mss_static_equals_the_program(disc, disc_file, program):
    mss = spinesim.MassSpringDisc(disc)
    s = mss.solve(motion_deg=[0, -0.1, 0, 0, 0, 0])
    p = program("mss", "--mesh", disc_file, "--motion", "0,-0.1,0,0,0,0")
    np.testing.assert_allclose(s.reaction_wrench, p["reaction_wrench"], rtol=1e-9, atol=1e-9)
    assert s.fields["green_lagrange_strain"].shape == (disc.num_tets, 6)
    # The network's internal forces balance at equilibrium: the plate pushes back up.
    assert s.reaction_wrench[1] > 0


def test_simulation_settles_to_the_static_equilibrium(disc):
    mss = spinesim.MassSpringDisc(disc)
    motion = [0, -0.1, 0, 0.2, 0, 0]
    static = mss.solve(motion_deg=motion)
    sim = mss.simulation(dt_s=1e-3)
    for k in range(1, 11):  # the plate ramped over 10 ms, then held
        sim.step(motion_deg=[k / 10 * x for x in motion])
    sim.step(motion_deg=motion, steps=990)
    assert math.isclose(sim.time_s, 1.0, rel_tol=1e-9)
    err = np.abs(sim.displacement_mm - static.displacement_mm).max()
    assert err < 1e-3 * np.abs(static.displacement_mm).max()
    np.testing.assert_allclose(sim.reaction_wrench(), static.reaction_wrench, rtol=1e-3,
                               atol=1e-3 * np.abs(static.reaction_wrench).max())
    sim.reset()
    assert sim.time_s == 0 and np.abs(sim.displacement_mm).max() == 0
    with pytest.raises(ValueError):
        sim.step(steps=0)


def test_calibration_brings_the_mss_to_the_fem(disc, tmp_path):
    tuned = tmp_path / "tuned.json"
    c = spinesim.calibrate(disc, train=["compression", "flexion"], holdout=["torsion"],
                           check=False, out=str(tuned))
    assert c.success and c.out == str(tuned)
    assert json.loads(tuned.read_text())["provenance"]["program"] == "spinesim"
    fem = spinesim.fem(disc, case="compression")
    untuned = spinesim.MassSpringDisc(disc).solve(case="compression")
    tuned_mss = spinesim.MassSpringDisc(disc, params=str(tuned)).solve(case="compression")

    def error(r):
        return np.abs(r.displacement_mm - fem.displacement_mm).max()

    assert error(tuned_mss) < 0.5 * error(untuned)


def test_spine_equals_the_program(program):
    s = spinesim.spine(forces={"T7": [0, 0, 300]})
    p = program("spine", "solve", "--force", "T7:0,0,300", quiet=False)
    assert s.converged and p["converged"]
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    assert_json_close(s.vertebrae, p["vertebrae"], rtol=1e-9, atol=1e-9)
    with pytest.raises(ValueError):
        spinesim.spine(forces={"T13": [0, 0, 1]})


def test_the_uncertain_inputs_equal_the_program(program):
    kw = dict(muscle_strength=0.8, joint_stiffness=1.2, ligament_stiffness=0.6,
              inclination_deg=15)
    s = spinesim.spine(disc_joints="fibre-reinforced", **kw)
    p = program("spine", "solve", "--disc-joints", "fibre-reinforced", "--muscle-strength", 0.8,
                "--joint-stiffness", 1.2, "--ligament-stiffness", 0.6, "--inclination", 15,
                quiet=False)
    for key, value in kw.items():
        assert s.options[key] == value == p["options"][key]
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    upright = spinesim.spine(disc_joints="fibre-reinforced")
    assert s.joints[15]["axial_n"] > upright.joints[15]["axial_n"] + 100  # leaning forward
    with pytest.raises(ValueError):
        spinesim.spine(muscle_strength=0)


def test_a_scaled_body_and_the_ligaments_equal_the_program(program):
    s = spinesim.spine(forces={"T1": [0, 0, 100]}, height_m=1.6, body_mass_kg=55, sex="female",
                       ligaments="on")
    p = program("spine", "solve", "--force", "T1:0,0,100", "--height", 1.6, "--mass", 55,
                "--sex", "female", "--ligaments", "on", quiet=False)
    assert s.options["subject"] == p["options"]["subject"]
    assert len(s.ligaments) == 17 * 6
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    with pytest.raises(ValueError, match="height"):
        spinesim.spine(height_m=2.5)
    with pytest.raises(ValueError, match="ligament"):
        spinesim.spine(ligaments="maybe")


def test_a_named_body_equals_the_program_and_its_own_numbers(program):
    bodies = spinesim.named_bodies()
    assert [b["name"] for b in bodies][0] == "p5-female"
    small = next(b for b in bodies if b["name"] == "p5-female")
    assert small["sex"] == "female" and "Hybrid III" in small["source"]
    s = spinesim.spine(subject="p5-female")
    p = program("spine", "solve", "--subject", "p5-female", quiet=False)
    assert s.options["subject"] == p["options"]["subject"]
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    by_hand = spinesim.spine(height_m=small["height_m"], body_mass_kg=small["body_mass_kg"],
                             sex="female")
    assert_json_close(s.joints, by_hand.joints, rtol=0, atol=0)
    with pytest.raises(ValueError, match="p95-male"):
        spinesim.spine(subject="giant")
    with pytest.raises(ValueError, match="whole body"):
        spinesim.seated_spine(subject="p5-female", height_m=1.6)


def test_the_rib_cage_equals_the_program_and_stiffens_the_thorax(program):
    s = spinesim.spine(forces={"T1": [0, 0, 100]}, rib_cage=True)
    p = program("spine", "solve", "--force", "T1:0,0,100", "--rib-cage", quiet=False)
    assert s.options["rib_cage"] and p["options"]["rib_cage"]
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    bare = spinesim.spine(forces={"T1": [0, 0, 100]})
    assert not bare.options["rib_cage"]

    def thoracic_flexion(r):
        turn = {v["name"]: v["rotation_deg"][0] for v in r.vertebrae}
        return turn["T1"] - turn["T12"]
    assert 0 < thoracic_flexion(s) < thoracic_flexion(bare)


def test_a_scoliotic_spine_equals_the_program(program):
    curve = {"type": "thoracic", "cobb_deg": 40, "apical_rotation_deg": 15}
    s = spinesim.spine(scoliosis=curve)
    p = program("spine", "solve", "--scoliosis", "thoracic", "--cobb", 40, "--apical-rotation",
                15, quiet=False)
    assert s.options["scoliosis"]["rest_posture"]["cobb_deg"] == pytest.approx(40, abs=1e-6)
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    left = spinesim.spine(scoliosis=dict(curve, convex="left"), muscles=False, gravity=False)
    assert left.options["scoliosis"]["convex"] == "left"
    with pytest.raises(ValueError, match="closes its disc"):
        spinesim.spine(scoliosis={"type": "lumbar", "cobb_deg": 100})
    with pytest.raises(ValueError, match="unknown key"):
        spinesim.spine(scoliosis={"type": "lumbar", "cobb_deg": 20, "cob": 3})


def test_seated_spine(program):
    s = spinesim.seated_spine(backrest_recline=110, lumbar_support=20)
    p = program("study", "seating", "--backrest-recline", 110, "--lumbar-support", 20)
    assert_json_close(s.joints, p["joints"], rtol=1e-9, atol=1e-6)
    assert_json_close(s.contacts, p["contacts"], rtol=1e-9, atol=1e-6)
    with pytest.raises(ValueError, match="backrest_recline"):
        spinesim.seated_spine(recline=110)


def test_study_file_round_trip(disc_file, tmp_path):
    study = tmp_path / "flexion.json"
    assert spinesim.main(["fem", "--mesh", str(disc_file), "--case", "flexion",
                          "--save-study", str(study), "--quiet"]) == 0
    r = spinesim.run_study(str(study))
    direct = spinesim.fem(spinesim.read_mesh(str(disc_file)), case="flexion")
    np.testing.assert_allclose(r.reaction_wrench, direct.reaction_wrench, rtol=1e-12, atol=1e-9)
    assert r.provenance["command"].startswith("spinesim run")
    assert any(i["path"].endswith("disc.vtu") for i in r.provenance["inputs"])


def test_wrong_study_names_the_field(tmp_path):
    study = tmp_path / "bad.json"
    study.write_text(json.dumps({"spinesim_study": 1, "verb": "fem",
                                 "options": {"mesh": "disc.vtu", "orderr": 2}}))
    with pytest.raises(ValueError, match="orderr"):
        spinesim.run_study(str(study))
    assert spinesim.main(["fem", "--no-such-flag"]) == 1


def test_outputs_name_the_script(disc, tmp_path):
    out = tmp_path / "f.vtu"
    spinesim.fem(disc, case="torsion", out=str(out))
    text = out.read_bytes()
    assert b"provenance" in text


def test_febio_export_prescribes_our_plate_motion(disc, tmp_path):
    import xml.etree.ElementTree as ET
    path = tmp_path / "flexion.feb"
    e = spinesim.export_febio(str(path), disc, case="flexion", material="fibre-reinforced")
    r = spinesim.fem(disc, case="flexion", material="fibre-reinforced")
    np.testing.assert_allclose(e.plate_motion_deg, r.plate_motion_deg, rtol=1e-12, atol=1e-14)
    root = ET.parse(path).getroot()
    assert root.tag == "febio_spec" and root.get("version") == "4.0"
    assert len(root.find("Mesh/Nodes")) == r.summary["fem_nodes"]
    assert sum(len(p) for p in root.findall("Mesh/Elements")) == disc.num_tets
    kinds = {m.get("type") for m in root.findall("Material/material")}
    assert kinds == {"isotropic elastic", "orthotropic elastic"}


def test_fibre_paths_set_from_python_are_followed_and_checked(disc, tmp_path):
    # Every annulus tet's fibres made circumferential-ish and flat: a fibre material follows them.
    assert disc.fibre_path_direction_1 is None
    n = disc.num_tets
    a = np.tile([1.0, 0.0, 0.0], (n, 1))
    b = np.tile([0.0, 0.0, 1.0], (n, 1))
    disc.fibre_path_direction_1, disc.fibre_path_direction_2 = a, b
    disc.validate()
    r = spinesim.fem(disc, case="compression", order=1, material="fibre-reinforced")
    annulus = disc.region == 1
    np.testing.assert_allclose(r.fields["fibre_direction_1"][annulus], a[annulus], atol=1e-15)
    np.testing.assert_allclose(r.fields["fibre_direction_2"][annulus], b[annulus], atol=1e-15)
    assert np.all(r.fields["fibre_angle_deg"][annulus] < 90.0)
    # They are written with the mesh and read back.
    disc.write(str(tmp_path / "paths.vtu"))
    back = spinesim.read_mesh(str(tmp_path / "paths.vtu"))
    np.testing.assert_array_equal(back.fibre_path_direction_2, b)
    # One family alone, or a direction that is not a unit vector, is refused.
    disc.fibre_path_direction_2 = 2 * b
    with pytest.raises(ValueError, match="fibre_path_direction_2"):
        disc.validate()
    disc.fibre_path_direction_2 = b[:-1]
    with pytest.raises(ValueError, match="rows for"):
        spinesim.fem(disc, case="compression", order=1, material="fibre-reinforced")
    disc.fibre_path_direction_1 = None
    assert disc.fibre_path_direction_2 is None


def test_peer_disc_imports_and_solves():
    import os
    folder = os.path.join(os.environ.get("SPINESIM_TESTDATA_DIR", "/nonexistent"),
                          "artisynth-lss", "fe-discs")
    if not os.path.exists(os.path.join(folder, "L45_NP.node")):
        pytest.skip("shared test data absent")
    disc = spinesim.import_artisynth(folder, "L4-L5")
    assert disc.num_nodes == 2149 and disc.num_tets % 6 == 0
    annulus = disc.region == 1
    np.testing.assert_allclose(np.linalg.norm(disc.fibre_path_direction_1[annulus], axis=1), 1.0)
    r = spinesim.fem(disc, case="torsion", order=1)
    axial = disc.frame_axes[:, 1]
    assert math.isclose(r.reaction_wrench[3:] @ axial, -7500.0, rel_tol=1e-6)
    # A fibre material follows the peer's fibres; without them, the annulus geometry.
    fib = spinesim.fem(disc, case="torsion", order=1, material="fibre-reinforced")
    np.testing.assert_allclose(fib.fields["fibre_direction_1"][annulus],
                               disc.fibre_path_direction_1[annulus], rtol=0, atol=1e-12)
    bare = spinesim.import_artisynth(folder, "L4-L5", fibre_paths=False)
    assert bare.fibre_path_direction_1 is None
    ours = spinesim.fem(bare, case="torsion", order=1, material="fibre-reinforced")
    assert not np.allclose(ours.fields["fibre_direction_1"], fib.fields["fibre_direction_1"])


def test_nonlinear_fem_is_linear_for_tiny_motions_and_balances_the_case(disc):
    # Tiny motions: the stress doubles with the motion, and the pressure is -tr/3. (Its equality
    # with the linear FEM's stress holds for the pointwise volume only: tests/fem.)
    q = np.array([0, -1e-4, 0, 1e-3, 0, 0])
    one = spinesim.fem(disc, motion_deg=q, order=1, nonlinear=True, increments=1)
    two = spinesim.fem(disc, motion_deg=2 * q, order=1, nonlinear=True, increments=1)
    s1, s2 = one.fields["cauchy_stress_MPa"], two.fields["cauchy_stress_MPa"]
    assert np.abs(s2 - 2 * s1).max() < 1e-3 * np.abs(s2).max()
    np.testing.assert_allclose(one.fields["pressure_MPa"], -s1[:, :3].sum(axis=1) / 3,
                               rtol=1e-10, atol=1e-16)
    # The case's moment is held.
    r = spinesim.fem(disc, case="flexion", material="fibre-reinforced", order=1, nonlinear=True,
                     increments=4)
    lateral = disc.frame_axes[:, 0]
    assert math.isclose(r.reaction_wrench[3:] @ lateral, -7500.0, rel_tol=1e-6)
    assert r.fields["fibre_stretch"].max() > 1.0
    n1 = r.fields["principal_stretch_direction_1"]
    np.testing.assert_allclose(np.linalg.norm(n1, axis=1), 1.0, rtol=0, atol=1e-12)

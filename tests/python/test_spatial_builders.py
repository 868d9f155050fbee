"""Spatial models built in Python (builders/spatial_builders.hpp, python/spatial_bindings.cpp):
a pendulum against its closed form, the heavy top and the world-placed four-bar equal to
their scene files, a clamped spatial beam against Euler-Bernoulli, and wrong arguments
raising exceptions that name them.

Run by CTest as part of python_bindings (tests/CMakeLists.txt).
"""
import math
import os

import numpy as np
import pytest

import flexmbd

SOURCE = os.environ.get("FLEXMBD_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
G = 9.81


def example(name):
    return os.path.join(SOURCE, "examples", name)


def pendulum(theta0, axis):
    """A steel bar 0.6 m x 20 mm x 20 mm hinged at one end at the world point (0.2, -0.1, 1.5)
    about the horizontal world axis `axis`, swung theta0 from hanging straight down."""
    scene = flexmbd.Scene("spatial pendulum")
    sys = scene.system
    length = 0.6
    props = flexmbd.shape_properties(flexmbd.SolidShape.box((length, 0.02, 0.02)), density=7800.0)
    pivot = np.array([0.2, -0.1, 1.5])
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    # body x along the bar: hanging down rotated by theta0 about the axis
    rot = flexmbd.rotation_from_axis_angle(a, theta0) @ flexmbd.rotation_from_axis_angle((0, 1, 0), math.pi / 2)
    # rotation_from_axis_angle((0, 1, 0), pi/2) takes body x to world -z: the bar hangs
    centre = pivot + rot @ np.array([length / 2, 0, 0])
    bar = sys.add_rigid_body_3d("bar", props, flexmbd.FrameState3d(position=centre, orientation=rot))
    sys.add_spatial_joint_at_world("pin", "revolute", "ground", bar, pivot, axis=a)
    sys.set_gravity((0, 0, -G))
    return scene, props, length


def zero_crossings(t, x):
    """Times where x crosses zero upwards (linear interpolation)."""
    k = np.nonzero((x[:-1] < 0) & (x[1:] >= 0))[0]
    return t[k] - x[k] * (t[k + 1] - t[k]) / (x[k + 1] - x[k])


def test_spatial_pendulum_follows_the_small_oscillation_period():
    theta0 = 0.02
    scene, props, length = pendulum(theta0, axis=(1, 1, 0))  # a horizontal axis along no body axis
    # closed form: T0 = 2 pi sqrt(I_O / (m g d)), I_O = m (L^2 + h^2) / 12 + m (L/2)^2 about the
    # hinge (the bar's transverse inertia from its box shape), d = L/2; finite amplitude:
    # T = T0 (1 + theta0^2 / 16 + ...) (Landau & Lifshitz sec. 11), 2.5e-5 here
    m = props.mass
    i_o = m * (length ** 2 + 0.02 ** 2) / 12 + m * (length / 2) ** 2
    omega0 = math.sqrt(m * G * length / 2 / i_o)
    period = 2 * math.pi / omega0 * (1 + theta0 ** 2 / 16)
    s = scene.solver
    s.t_end = 4.0
    s.output_step = 1e-3
    s.rtol, s.atol = 1e-10, 1e-12
    res = scene.run()
    assert "pin.angle" in res and "pin.angle_dot" in res  # the joint output columns
    theta = res["pin.angle"]
    # the joint angle starts at 0 (frames placed in the initial configuration) and swings
    # between -2 theta0 and 0 about the hanging angle -theta0 (the sign: the rotation of
    # the bar's frame about the axis is -theta0 back to hanging)
    assert theta[0] == pytest.approx(0.0, abs=1e-12)
    assert np.min(theta) == pytest.approx(-2 * theta0, rel=1e-5)  # energy conservation at rtol 1e-10
    crossings = zero_crossings(res.t, theta + theta0)
    measured = np.mean(np.diff(crossings))
    # tolerance: the O(theta0^4) terms of the period (~1e-9), linear interpolation of the
    # crossings at output step 1e-3 s (error ~ h^2 theta''/theta' ~ 1e-7 relative) and the
    # integration (rtol 1e-10): 1e-6 relative covers them with margin
    assert measured == pytest.approx(period, rel=1e-6)
    # modes at rest (at=None): the static equilibrium hanging down, the small-oscillation frequency
    scene2, _, _ = pendulum(0.0, axis=(1, 1, 0))
    modes = scene2.modes(count=1)
    # modes about the equilibrium the solver finds (residual at its tolerances): 1e-6
    assert modes[0]["omega"] == pytest.approx(omega0, rel=1e-6)


def heavy_top_in_python():
    """examples/heavy_top.json built in Python."""
    scene = flexmbd.Scene("heavy top")
    sys = scene.system
    disc = flexmbd.SolidShape.cylinder(radius=0.05, length=0.02, axis="z")
    top = sys.add_rigid_body_3d(
        "top", flexmbd.shape_properties(disc, mass=1.0),
        flexmbd.FrameState3d(position=(0, -0.049999999999999996, 0.08660254037844388),
                             orientation=((1, 0, 0), 0.5235987755982988),
                             velocity=(0.14052074486221316, 0, 0),
                             angular_velocity=(0, 1.4052074486221315, 300.0)))
    sys.add_spatial_joint_at_world("tip", flexmbd.SpatialJointType.SPHERICAL, "ground", top, point=(0, 0, 0))
    sys.set_gravity((0, 0, -9.81))
    scene.add_output({"type": "energy"})
    s = scene.solver
    s.t_end, s.output_step, s.rtol, s.atol = 2.3400000000000003, 0.002, 1e-9, 1e-11
    return scene


def test_heavy_top_built_in_python_equals_its_scene_file():
    t_end = 0.3  # 14 spin turns: the comparison is exact, the whole precession is not needed
    built = heavy_top_in_python()
    built.solver.t_end = t_end
    from_file = flexmbd.load_scene(example("heavy_top.json"), overrides={"solver.t_end": t_end})
    a, b = built.run(), from_file.run()
    assert a.columns == b.columns
    assert "tip.rx" in a.columns and "energy.total" in a.columns
    np.testing.assert_array_equal(a.data, b.data)  # the same model: the same numbers, bit for bit
    # and the physics: energy conserved over the run to the integration tolerance
    e = a["energy.total"]
    assert np.max(np.abs(e - e[0])) < 1e-6 * abs(e[0]) + 1e-6


def test_world_placed_four_bar_built_in_python_equals_its_scene_file():
    scene = flexmbd.Scene("four-bar")
    sys = scene.system
    bars = {  # name: (length, centre, angle about z), from examples/spatial_four_bar.json
        "crank": (0.2, (0.05000000000000002, 0.08660254037844387, 0.0), 1.0471975511965976),
        "coupler": (0.5, (0.32605261688395537, 0.2799768672920755, 0.0), 0.4412688833019245),
        "rocker": (0.4, (0.5010526168839553, 0.19337432691363166, 0.0), 1.3126765347553853),
    }
    for name, (length, centre, angle) in bars.items():
        props = flexmbd.shape_properties(flexmbd.SolidShape.box((length, 0.02, 0.02)), density=7800)
        sys.add_rigid_body_3d(name, props, flexmbd.FrameState3d(position=centre, orientation=((0, 0, 1), angle)))
    z = (0, 0, 1)
    sys.add_spatial_joint_at_world("A", "revolute", "ground", "crank", (0.0, 0.0, 0.0), axis=z)
    sys.add_spatial_joint_at_world("B", "revolute", "crank", "coupler", (0.10000000000000003, 0.17320508075688773, 0.0), axis=z)
    sys.add_spatial_joint_at_world("C", "revolute", "coupler", "rocker", (0.5521052337679107, 0.3867486538272633, 0.0), axis=z)
    sys.add_spatial_joint_at_world("D", "revolute", "ground", "rocker", (0.45, 0.0, 0.0), axis=z)
    sys.set_gravity((0, -9.81, 0))
    scene.add_output({"type": "energy"})
    s = scene.solver
    s.t_end, s.output_step, s.rtol, s.atol = 0.5, 0.01, 1e-8, 1e-10
    a = scene.run()
    b = flexmbd.load_scene(example("spatial_four_bar.json"), overrides={"solver.t_end": 0.5}).run()
    assert a.columns == b.columns
    assert {"A.angle", "B.angle_dot", "D.angle"} <= set(a.columns)
    np.testing.assert_array_equal(a.data, b.data)
    assert a.summary["redundant_constraints"] == b.summary["redundant_constraints"]
    assert len(a.summary["redundant_constraints"]) == 3  # the planar loop's out-of-plane equations


def test_a_driven_spatial_joint_follows_its_law():
    scene = flexmbd.Scene("driven")
    sys = scene.system
    arm = sys.add_rigid_body_3d("arm", flexmbd.RigidBody3dProperties(mass=2.0, inertia=(0.01, 0.02, 0.03)),
                                flexmbd.FrameState3d(position=(0.5, 0, 1)))
    slide = sys.add_rigid_body_3d("slide", flexmbd.RigidBody3dProperties(mass=1.0, inertia=np.diag([0.01, 0.01, 0.01])),
                                  flexmbd.FrameState3d(position=(0.5, 0, 0)))
    hinge = sys.add_spatial_joint_at_world("hinge", "revolute", "ground", arm, (0, 0, 1), axis=(0, 0, 1))
    # frames with the same axes (z along world y) on the ground and on the slide
    prism = sys.add_spatial_joint("rail", "prismatic", "ground", flexmbd.JointFrame((0.5, 0, 0), axis=(0, 1, 0)),
                                  slide, flexmbd.JointFrame(axis=(0, 1, 0)))
    sys.add_joint_angle_driver("motor", hinge, flexmbd.constant_speed_law(2.0))
    sys.add_joint_displacement_driver("push", prism, flexmbd.harmonic_law(0.1, 3.0))
    sys.add_spatial_rotational_spring_damper("rs", hinge, stiffness=5.0, damping=0.1)
    sys.add_spatial_applied_load("wind", slide, force_x=flexmbd.constant_law(1.0))
    sys.set_gravity((0, 0, -9.81))
    scene.add_output({"type": "point", "name": "tip", "body": "arm", "point": [0.5, 0, 0]})
    scene.solver.t_end = 1.0
    res = scene.run()
    t = res.t
    # constraints hold to the integration tolerance (rtol 1e-6 default, atol 1e-8): 1e-6
    np.testing.assert_allclose(res["hinge.angle"], 2.0 * t, atol=1e-6)
    np.testing.assert_allclose(res["rail.displacement"], 0.1 * np.sin(3.0 * t), atol=1e-6)
    np.testing.assert_allclose(res["slide.y"], 0.1 * np.sin(3.0 * t), atol=1e-6)
    np.testing.assert_allclose(res["tip.x"], np.cos(2.0 * t), atol=1e-6)  # arm centre at 0.5 + tip 0.5
    np.testing.assert_allclose(res["tip.y"], np.sin(2.0 * t), atol=1e-6)


def test_clamped_spatial_beam_modes_follow_euler_bernoulli():
    length, width, e_mod, rho = 1.0, 0.02, 2.1e11, 7800.0
    section = flexmbd.rectangular_section_3d(width, width, youngs_modulus=e_mod, poisson_ratio=0.3, density=rho)
    mesh = flexmbd.BeamMesh3d.straight(length, 8, section)
    model = flexmbd.FfrBeamModel3d(mesh, flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.CLAMPED, modes=4))
    scene = flexmbd.Scene("cantilever")
    sys = scene.system
    beam = sys.add_flexible_body_3d("beam", model)
    sys.add_spatial_joint("clamp", "fixed", "ground", flexmbd.JointFrame(), beam, flexmbd.JointFrame())
    # Euler-Bernoulli cantilever: omega_1 = 1.8751^2 sqrt(E I / (rho A L^4)) (square section:
    # the two bending directions together)
    omega1 = 1.8751040687 ** 2 * math.sqrt(e_mod * width ** 4 / 12 / (rho * width ** 2 * length ** 4))
    # 8 cubic elements: the first frequency converges as h^4 (2.1e-6 high here); 1e-4 with margin
    assert model.natural_frequencies()[0] == pytest.approx(omega1, rel=1e-4)
    modes = scene.modes(count=2)  # at rest: the beam on its clamp, frame fixed
    assert [m["omega"] for m in modes] == pytest.approx([omega1, omega1], rel=1e-4)
    scene.solver.t_end = 0.01
    res = scene.run()
    assert res.ok and "beam.q1" in res.columns


def test_rayleigh_option_lowers_bending_by_the_rotary_inertia():
    # A simply supported (pinned-pinned frame) square steel beam, L/h = 10: the first
    # bending frequency of the Rayleigh beam over the Euler-Bernoulli one is
    # 1 / sqrt(1 + r^2 k^2), r^2 = I / A = h^2 / 12, k = pi / L (the continuum). The two
    # 16-element models share their discretisation error to ~1e-7; 1e-5 with margin.
    length, width = 1.0, 0.1
    section = flexmbd.rectangular_section_3d(width, width, youngs_modulus=2.1e11, poisson_ratio=0.3, density=7800.0)
    mesh = flexmbd.BeamMesh3d.straight(length, 16, section)

    def first(theory):
        options = flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.PINNED_PINNED, theory=theory)
        return flexmbd.FfrBeamModel3d(mesh, options).natural_frequencies()[0]

    ratio = first(flexmbd.BeamTheory.RAYLEIGH) / first(flexmbd.BeamTheory.EULER_BERNOULLI)
    expected = 1.0 / math.sqrt(1.0 + width ** 2 / 12.0 * (math.pi / length) ** 2)
    assert ratio == pytest.approx(expected, rel=1e-5)


def test_timoshenko_option_adds_the_shear_flexibility_of_a_cantilever():
    # The rectangle's shear factor is Cowper's, kappa = 10 (1 + nu) / (12 + 11 nu); a thick
    # clamped beam (L/h = 3) is softer under Timoshenko than under Rayleigh by its shear
    # flexibility (the first frequency ~6 % lower; the closed forms are checked in C++,
    # tests/test_timoshenko.cpp); a section given by its constants needs the factors.
    length, width, nu, E = 0.3, 0.1, 0.3, 2.1e11
    section = flexmbd.rectangular_section_3d(width, width, youngs_modulus=E, poisson_ratio=nu, density=7800.0)
    assert section.shear_factor_y == pytest.approx(10 * (1 + nu) / (12 + 11 * nu), rel=1e-14)
    mesh = flexmbd.BeamMesh3d.straight(length, 8, section)

    def first(theory):
        options = flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.CLAMPED, theory=theory)
        return flexmbd.FfrBeamModel3d(mesh, options).natural_frequencies()[0]

    assert first(flexmbd.BeamTheory.TIMOSHENKO) < 0.97 * first(flexmbd.BeamTheory.RAYLEIGH)
    general = flexmbd.BeamSection3d(area=section.area, inertia_y=section.inertia_y, inertia_z=section.inertia_z,
                                    torsion_constant=section.torsion_constant, youngs_modulus=E, poisson_ratio=nu,
                                    density=7800.0)
    options = flexmbd.FfrBeamOptions3d(theory=flexmbd.BeamTheory.TIMOSHENKO)
    with pytest.raises(flexmbd.InputError, match="shear_factor_y"):
        flexmbd.FfrBeamModel3d(flexmbd.BeamMesh3d.straight(length, 2, general), options)


def test_placed_shapes_make_a_dumbbell_of_the_closed_form_inertia():
    # two spheres (m_s, r) at +-d on body x and a rod (m_c, radius r_c, length 2d) along x:
    # Ixx = 2 (2/5 m_s r^2) + m_c r_c^2 / 2, Iyy = Izz = 2 (2/5 m_s r^2 + m_s d^2) + m_c (3 r_c^2 + 4 d^2) / 12
    ms, r, d, mc, rc = 1.5, 0.05, 0.3, 0.4, 0.01
    ball = flexmbd.SolidShape.sphere(r)
    rod = flexmbd.SolidShape.cylinder(rc, 2 * d, axis="z").placed((0, 0, 0), orientation=((0, 1, 0), math.pi / 2))
    parts = [flexmbd.ShapePart(ball.placed((-d, 0, 0)), mass=ms), flexmbd.ShapePart(ball.placed((d, 0, 0)), mass=ms),
             flexmbd.ShapePart(rod, mass=mc)]
    props = flexmbd.shape_properties(parts)
    ixx = 2 * 0.4 * ms * r ** 2 + mc * rc ** 2 / 2
    iyy = 2 * (0.4 * ms * r ** 2 + ms * d ** 2) + mc * (3 * rc ** 2 + 4 * d ** 2) / 12
    # exact formulas: rounding only (1e-14 relative)
    np.testing.assert_allclose(props.inertia, np.diag([ixx, iyy, iyy]), rtol=0, atol=1e-14 * iyy)
    assert props.mass == pytest.approx(2 * ms + mc, rel=1e-15)
    # one ball only: the centre of mass moves to m_s d / (m_s + m_c), and such a body is refused
    c = flexmbd.composite_inertia(parts[1:])
    assert c.centre_of_mass[0] == pytest.approx(ms * d / (ms + mc), rel=1e-14)
    with pytest.raises(flexmbd.InputError, match="centre of mass is at"):
        flexmbd.shape_properties(parts[1:])


def test_a_bushing_placed_in_the_world_equals_its_scene_form():
    # the same mount built in Python and read from a scene: the same numbers, bit for bit;
    # and it starts undeflected (the body at rest stays where it is)
    scene_json = {"name": "mount", "dimension": 3,
                  "bodies": [{"name": "b", "type": "rigid", "mass": 2, "inertia": [0.04, 0.045, 0.05],
                              "position": [0.3, 0.2, 0.1], "orientation": {"axis": [1, 2, 3], "angle": 0.7},
                              "velocity": [0.005, 0.005, 0]}],
                  "forces": [{"name": "mount", "type": "bushing", "bodies": ["ground", "b"],
                              "world": {"point": [0.3, 0.2, 0.1], "axis": [1, 1, 0]},
                              "stiffness": [500, 600, 800, 30, 40, 20]}],
                  "solver": {"t_end": 0.2, "output_step": 0.01}}
    from_file = flexmbd.scene_from_dict(scene_json)
    built = flexmbd.Scene("mount")
    sys = built.system
    b = sys.add_rigid_body_3d("b", flexmbd.RigidBody3dProperties(mass=2, inertia=(0.04, 0.045, 0.05)),
                              flexmbd.FrameState3d(position=(0.3, 0.2, 0.1), orientation=((1, 2, 3), 0.7),
                                                   velocity=(0.005, 0.005, 0)))
    sys.add_spatial_bushing_at_world("mount", "ground", b, flexmbd.world_joint_frame((0.3, 0.2, 0.1), (1, 1, 0)),
                                     stiffness=(500, 600, 800, 30, 40, 20))
    built.solver.t_end, built.solver.output_step = 0.2, 0.01
    a, c = built.run(), from_file.run()
    assert a.columns == c.columns
    np.testing.assert_array_equal(a.data, c.data)
    # the push along (1, 1, 0) stays along it: b.x - 0.3 == b.y - 0.2 (1e-9: rtol 1e-6 of 0.6 mm)
    np.testing.assert_allclose(a["b.x"] - 0.3, a["b.y"] - 0.2, atol=1e-9)
    assert np.max(np.abs(a["b.x"] - 0.3)) > 1e-4


def test_a_body_of_given_invariants_is_the_body_of_its_beam_model():
    # The clamped beam as a body of its model and as a body of the model's invariants: the
    # same equations, so the same modes (1e-10: two eigen-solves of one matrix); k_ff
    # doubled in the given invariants raises every frequency by sqrt(2) (omega^2 = k/m).
    section = flexmbd.rectangular_section_3d(0.02, 0.02, youngs_modulus=2.1e11, poisson_ratio=0.3, density=7800.0)
    model = flexmbd.FfrBeamModel3d(flexmbd.BeamMesh3d.straight(1.0, 6, section),
                                   flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.CLAMPED, modes=4))

    def clamped(body_model):
        scene = flexmbd.Scene("cantilever")
        beam = scene.system.add_flexible_body_3d("beam", body_model)
        scene.system.add_spatial_joint("clamp", "fixed", "ground", flexmbd.JointFrame(), beam, flexmbd.JointFrame())
        return [m["omega"] for m in scene.modes(count=3)]

    inv = model.invariants
    assert isinstance(inv, flexmbd.FfrInvariants3d) and inv.num_elastic == 4 and len(inv.points) == 7
    assert inv.mass == pytest.approx(7800.0 * 0.02 ** 2 * 1.0, rel=1e-14)
    reference = clamped(model)
    assert clamped(inv) == pytest.approx(reference, rel=1e-10)
    inv.k_ff = 2.0 * inv.k_ff
    assert clamped(inv) == pytest.approx([math.sqrt(2.0) * w for w in reference], rel=1e-10)
    inv.m_ff = -inv.m_ff
    with pytest.raises(flexmbd.InputError, match="m_ff"):
        flexmbd.Scene("bad").system.add_flexible_body_3d("beam", inv)


ROTOR = os.path.join(SOURCE, "..", "shared", "data", "exudyn-rotor")


@pytest.mark.skipif(not os.path.exists(os.path.join(ROTOR, "rotorDiscTest.inp")), reason="no rotor data in ../shared")
def test_an_fe_body_from_python_is_the_scene_body():
    # EXUDYN's rotor from its Abaqus export: the first free-free frequency equals the
    # published 104.63701326 Hz (1e-6, as tests/test_fe_import.cpp), and the body added from
    # the model's invariants has the coordinates of the scene's fe_body of the same files
    # (tests/test_fe_scene.cpp compares their invariants); errors name the node or file.
    data = flexmbd.read_abaqus_fe(os.path.join(ROTOR, "rotorDiscTest.inp"),
                                  os.path.join(ROTOR, "rotorDiscTestMASS1.mtx"),
                                  os.path.join(ROTOR, "rotorDiscTestSTIF1.mtx"))
    assert data.num_nodes == 115 and data.num_dofs == 345
    model = flexmbd.FeBodyModel(data, modes=4, stiffness_scale=0.01, point_masses=[(10, 0.1)])
    assert model.natural_frequencies[0] / (2 * math.pi) == pytest.approx(104.6, rel=5e-3)  # with the unbalance
    plain = flexmbd.FeBodyModel(data, modes=4, stiffness_scale=0.01)
    assert plain.natural_frequencies[0] / (2 * math.pi) == pytest.approx(104.63701326, rel=1e-6)
    inv = model.invariants
    assert inv.mass == pytest.approx(plain.invariants.mass + 0.1, rel=1e-13)
    scene = flexmbd.Scene("rotor")
    scene.system.add_flexible_body_3d("rotor", inv)
    text = {"dimension": 3, "bodies": [{"type": "fe_body", "name": "rotor", "modes": 4, "stiffness_scale": 0.01,
                                        "point_masses": [{"node": 10, "mass": 0.1}],
                                        "abaqus": {"input": os.path.join(ROTOR, "rotorDiscTest.inp"),
                                                   "mass": os.path.join(ROTOR, "rotorDiscTestMASS1.mtx"),
                                                   "stiffness": os.path.join(ROTOR, "rotorDiscTestSTIF1.mtx")}}]}
    from_scene = flexmbd.scene_from_dict(text)
    scene.system.finalize()
    assert from_scene.system.coordinate_names() == scene.system.coordinate_names()
    assert len(scene.system.coordinate_names()) == 7 + 4
    # Craig-Bampton on rigid interfaces over the shaft's end faces (the node numbers at
    # z = 0 and z = 0.5): 6 constraint modes of the free end and 4 fixed-interface modes,
    # the two frames appended to the 115 nodes as attachment points
    ends = {0.0: [], 0.5: []}
    for node, x in zip(data.node_ids, data.coordinates):
        for z in ends:
            if abs(x[2] - z) < 1e-6:
                ends[z].append(node)
    cb = flexmbd.FeBodyModel(data, modes=4, stiffness_scale=0.01, reduction="craig_bampton", reference="bottom",
                             interfaces=[{"name": "bottom", "kind": "rigid", "nodes": ends[0.0]},
                                         {"name": "top", "kind": "rigid", "nodes": ends[0.5]}])
    assert cb.invariants.num_elastic == 6 + 4 and len(cb.invariants.points) == 115 + 2
    assert len(cb.natural_frequencies) == 4
    with pytest.raises(flexmbd.InputError, match="interface 'x'.*no node set 'nope'"):
        flexmbd.FeBodyModel(data, interfaces=[{"name": "x", "kind": "rigid", "node_set": "nope"}])
    with pytest.raises(flexmbd.InputError, match="point_masses: no node 9999"):
        flexmbd.FeBodyModel(data, point_masses=[(9999, 1.0)])
    with pytest.raises(flexmbd.InputError, match="no_such.inp"):
        flexmbd.read_abaqus_fe("no_such.inp", "m.mtx", "k.mtx")


@pytest.mark.parametrize("call, error, words", [
    (lambda: flexmbd.FrameState3d(position="up"), TypeError, "FrameState3d: position must be 3 numbers"),
    (lambda: flexmbd.FrameState3d(orientation=[[1, 0, 0], [0, 2, 0], [0, 0, 1]]), flexmbd.InputError,
     "FrameState3d: orientation is not a rotation matrix"),
    (lambda: flexmbd.FrameState3d(orientation="z"), TypeError, "FrameState3d: orientation must be a rotation"),
    (lambda: flexmbd.FrameState3d(orientation=((0, 0, 0), 1.0)), flexmbd.InputError, "orientation: the axis must be"),
    (lambda: flexmbd.RigidBody3dProperties(mass=-1.0, inertia=(1, 1, 1)), flexmbd.InputError,
     "RigidBody3dProperties: mass must be > 0, got -1.0"),
    (lambda: flexmbd.RigidBody3dProperties(mass=1.0, inertia=(1, 0, 1)), flexmbd.InputError, "inertia[1] must be > 0"),
    (lambda: flexmbd.RigidBody3dProperties(mass=1.0, inertia="heavy"), TypeError, "inertia must be 3 principal moments"),
    (lambda: flexmbd.shape_properties(flexmbd.SolidShape.sphere(0.1)), flexmbd.InputError, "exactly one of mass or density"),
    (lambda: flexmbd.SolidShape.cylinder(0.1, 1.0, axis="w"), flexmbd.InputError, "axis must be \"x\", \"y\" or \"z\""),
    (lambda: flexmbd.rectangular_section_3d(0.1, 0.1, youngs_modulus=1e9, density=1000), flexmbd.InputError,
     "exactly one of shear_modulus or poisson_ratio"),
    (lambda: flexmbd.BeamMesh3d.straight(1.0, 2.5, flexmbd.circular_section_3d(0.01, 1e9, 4e8, density=1000)),
     TypeError, "elements must be an integer"),
])
def test_wrong_objects_raise_errors_naming_the_argument(call, error, words):
    with pytest.raises(error) as e:
        call()
    assert words in str(e.value)


def test_wrong_builder_arguments_raise_errors_naming_them():
    sys = flexmbd.Scene("bad").system
    props = flexmbd.RigidBody3dProperties(mass=1.0, inertia=(1, 1, 1))
    b = sys.add_rigid_body_3d("b", props)
    prism = sys.add_spatial_joint_at_world("p", "prismatic", "ground", b, (0, 0, 0), axis=(1, 0, 0))
    cases = [
        (lambda: sys.add_rigid_body_3d("c", 1.0), TypeError, "add_rigid_body_3d: properties must be RigidBody3dProperties"),
        (lambda: sys.add_rigid_body_3d("c", props, initial=(0, 0, 0)), TypeError, "initial must be a FrameState3d"),
        (lambda: sys.add_spatial_joint_at_world("h", "hinge", "ground", b, (0, 0, 0)), flexmbd.InputError,
         "type: unknown spatial joint type 'hinge' (expected one of: spherical, revolute"),
        (lambda: sys.add_spatial_joint_at_world("h", "revolute", "ground", b, (0, 0, 0)), flexmbd.InputError,
         "joint 'h': a revolute joint needs its axis"),
        (lambda: sys.add_spatial_joint_at_world("u", "universal", "ground", b, (0, 0, 0), axis=(0, 0, 1)),
         flexmbd.InputError, "a universal joint needs x_axis"),
        (lambda: sys.add_spatial_joint_at_world("h", "revolute", 3.5, b, (0, 0, 0), axis=(0, 0, 1)), TypeError,
         "add_spatial_joint_at_world: body_i must be a body name or a BodyIndex, got 3.5"),
        (lambda: sys.add_spatial_joint_at_world("h", "revolute", "nobody", b, (0, 0, 0), axis=(0, 0, 1)),
         flexmbd.InputError, "nobody"),
        (lambda: sys.add_spatial_joint_at_world("h", "revolute", "ground", b, (0, 0), axis=(0, 0, 1)), TypeError,
         "point must be 3 numbers"),
        (lambda: sys.add_spatial_joint("h", "spherical", "ground", (0, 0, 0), b, None), TypeError,
         "frame_i must be a JointFrame"),
        (lambda: sys.add_joint_angle_driver("d", prism, flexmbd.constant_law(0.0)), flexmbd.InputError,
         "driver 'd': a joint angle driver needs a revolute or cylindrical joint, but joint 'p' is prismatic"),
        (lambda: sys.add_joint_displacement_driver("d", prism, "fast"), TypeError, "law must be a time law"),
        (lambda: sys.add_spatial_spring_damper("s", "ground", (0, 0, 0), b, (0, 0, 0), stiffness=-1.0),
         flexmbd.InputError, "stiffness must be >= 0"),
        (lambda: sys.add_spatial_bushing("k", "ground", None, b, None, stiffness=(1, 2, 3)), TypeError,
         "stiffness must be 6 numbers"),
        (lambda: sys.add_spatial_applied_load("f", b), flexmbd.InputError, "no force or torque law given"),
        (lambda: sys.set_gravity("down"), TypeError, "gravity must be 2 numbers (planar) or 3 numbers"),
    ]
    for call, error, words in cases:
        with pytest.raises(error) as e:
            call()
        assert words in str(e.value), str(e.value)


def test_sid_round_trip_from_python(tmp_path):
    # A reduced cantilever's invariants written as SID and read back: the same invariants
    # to round-off (the file holds 17 digits; the reader recombines blocks: 1e-13 of each
    # matrix's largest entry), and a file that is not a SID raises InputError naming it.
    section = flexmbd.rectangular_section_3d(0.02, 0.02, youngs_modulus=2.1e11, poisson_ratio=0.3, density=7800.0)
    model = flexmbd.FfrBeamModel3d(flexmbd.BeamMesh3d.straight(1.0, 8, section),
                                   flexmbd.FfrBeamOptions3d(reference=flexmbd.Reference3d.CLAMPED, modes=4))
    inv = model.invariants
    path = str(tmp_path / "beam.SID_FEM")
    flexmbd.write_sid(inv, path)
    back = flexmbd.read_sid(path)
    for name in ("m_ff", "k_ff", "s_bar", "second_moment"):
        a, b = np.asarray(getattr(inv, name)), np.asarray(getattr(back, name))
        assert np.max(np.abs(a - b)) <= 1e-13 * np.max(np.abs(a))
    bad = tmp_path / "bad.SID_FEM"
    bad.write_text("part\nnew model\n")
    with pytest.raises(flexmbd.InputError, match="bad.SID_FEM, line 2"):
        flexmbd.read_sid(str(bad))

"""User functions from Python (docs/python.md, "User functions"):
Python callables as time laws (torques, loads, drivers) and spring-damper laws, run with
the GIL released and taken only inside the callable; an exception in a callable ends the
run as a solver failure with its message and the results so far."""

import math
import threading

import numpy as np
import pytest

import flexmbd

# ---- a Python torque law equals the same law as a scene time law, bit for bit ------------

A, W = 2.0, 5.0  # torque amplitude (N m) and circular frequency (rad/s)

PENDULUM = {
    "name": "driven pendulum",
    "gravity": [0.0, -9.81],
    "bodies": [{"name": "rod", "type": "rigid", "mass": 1.0, "inertia": 1.0 / 12.0,
                "com": [0.0, 0.0], "position": [0.5, 0.0], "angle": 0.0}],
    "joints": [{"name": "pin", "type": "revolute", "bodies": ["ground", "rod"],
                "points": [[0.0, 0.0], [-0.5, 0.0]]}],
    "forces": [{"name": "motor", "type": "applied_load", "body": "rod",
                "torque": {"type": "harmonic", "amplitude": A, "omega": W}}],
    "solver": {"t_end": 1.0, "output_step": 0.01, "rtol": 1e-8, "atol": 1e-10},
}


def _python_pendulum(torque):
    """The scene above built in Python, its torque law given by `torque`."""
    scene = flexmbd.Scene("driven pendulum")
    sys_ = scene.system
    sys_.set_gravity((0.0, -9.81))
    rod = sys_.add_rigid_body("rod", flexmbd.RigidBodyProperties(mass=1.0, inertia=1.0 / 12.0),
                              flexmbd.FrameState2d(position=(0.5, 0.0)))
    sys_.add_revolute_joint("pin", "ground", (0.0, 0.0), rod, (-0.5, 0.0))
    sys_.add_applied_load("motor", rod, (0.0, 0.0), torque=torque)
    scene.solver.t_end, scene.solver.output_step = 1.0, 0.01
    scene.solver.rtol, scene.solver.atol = 1e-8, 1e-10
    return scene


def test_python_torque_law_equals_the_scene_time_law_bit_for_bit():
    # the harmonic law computes offset + A sin(omega t + phase) (core/time_law.cpp); the
    # callable does the same operations with the same libm sin, so every residual is the
    # same number and so is every row of the results
    scene_run = flexmbd.scene_from_dict(PENDULUM).run()
    python_run = _python_pendulum(lambda t: 0.0 + A * math.sin(W * t + 0.0)).run()
    assert python_run.columns == scene_run.columns
    assert python_run.data.shape == scene_run.data.shape
    assert np.array_equal(python_run.data, scene_run.data)
    assert python_run.summary["steps"] == scene_run.summary["steps"]


def test_python_driver_law_with_its_derivatives_equals_the_scene_law_bit_for_bit():
    # constant_speed: f = initial + speed t, f' = speed, f'' = 0 (core/time_law.cpp)
    def build(law):
        scene = flexmbd.Scene("crank")
        sys_ = scene.system
        crank = sys_.add_rigid_body("crank", flexmbd.RigidBodyProperties(mass=1.0, inertia=0.1, com=(0.5, 0)))
        pin = sys_.add_revolute_joint("O1", "ground", (0, 0), crank, (0, 0))
        sys_.add_joint_driver("motor", pin, law)
        scene.solver.t_end = 0.5
        return scene.run()

    scene_law = build(flexmbd.constant_speed_law(2.0))
    user_law = build(flexmbd.user_law(lambda t: 0.0 + 2.0 * t, derivative=lambda t: 2.0,
                                      second_derivative=lambda t: 0.0))
    assert np.array_equal(user_law.data, scene_law.data)


# ---- a Python spring law against the closed form -----------------------------------------

M, K, C, L0, X0 = 2.0, 50.0, 0.8, 1.0, 1.3  # kg, N/m, N s/m, m, m


def _slider(law):
    scene = flexmbd.Scene("slider on a spring")
    sys_ = scene.system
    slider = sys_.add_rigid_body("slider", flexmbd.RigidBodyProperties(mass=M, inertia=0.1),
                                 flexmbd.FrameState2d(position=(X0, 0.0)))
    sys_.add_prismatic_joint("rail", "ground", (0, 0), slider, (0, 0), axis=(1, 0))
    sys_.add_spring_damper("spring", "ground", (0, 0), slider, (0, 0), law=law)
    scene.solver.t_end, scene.solver.output_step = 3.0, 0.01
    return scene


def _closed_form(t):
    # m u'' + c u' + k u = 0, u = x - l0, u(0) = x0 - l0, u'(0) = 0, underdamped:
    # u = e^(-zeta wn t) (u0 cos(wd t) + zeta wn u0 / wd sin(wd t)) (Rao, Mechanical Vibrations, 2.6)
    wn = math.sqrt(K / M)
    zeta = C / (2.0 * math.sqrt(K * M))
    wd = wn * math.sqrt(1.0 - zeta * zeta)
    u0 = X0 - L0
    return L0 + np.exp(-zeta * wn * t) * (u0 * np.cos(wd * t) + zeta * wn * u0 / wd * np.sin(wd * t))


@pytest.mark.parametrize("with_derivative", [False, True])
def test_python_spring_law_follows_the_closed_form(with_derivative):
    f = lambda t, l, ldot: K * (l - L0) + C * ldot  # noqa: E731
    law = flexmbd.spring_law(f, derivative=lambda t, l, ldot: (K, C)) if with_derivative else f
    res = _slider(law).run()
    assert res.ok, res.message
    error = np.max(np.abs(res["slider.x"] - _closed_form(res.t)))
    # BDF at rtol 1e-8, atol 1e-10 over ~3.4 periods: a global error of a few hundred
    # rtol times the amplitude 0.3 m; 1e-5 m bounds it (0.003 % of the amplitude)
    assert error < 1e-5, error


def test_finite_difference_derivatives_agree_with_the_user_ones():
    f = lambda t, x, xdot: 40.0 * (x - 0.5) + 0.3 * xdot + 7.0 * x ** 3  # noqa: E731
    fd = flexmbd.spring_law(f)
    exact = flexmbd.spring_law(f, derivative=lambda t, x, xdot: (40.0 + 21.0 * x * x, 0.3))
    assert not fd.has_user_derivative and exact.has_user_derivative
    v, dx, dv = fd(0.3, 0.8, -1.5)
    w, ex, ev = exact(0.3, 0.8, -1.5)
    assert v == w == f(0.3, 0.8, -1.5)
    # central differences, h = eps^(1/3) max(|x|, 1) ~ 6e-6: error h^2 |f'''| / 6 + eps |f| / h ~ 1e-10
    assert abs(dx - ex) < 1e-8 * abs(ex)
    assert abs(dv - ev) < 1e-8
    # a time law: f' and f'' by central differences (h1 = eps^(1/3), h2 = eps^(1/4) times max(|t|, 1))
    g, dg, ddg = flexmbd.user_law(lambda t: math.sin(3.0 * t) + t * t)(0.7)
    assert g == math.sin(3.0 * 0.7) + 0.7 * 0.7
    assert abs(dg - (3.0 * math.cos(2.1) + 1.4)) < 1e-9      # truncation ~2e-10, rounding ~4e-11
    assert abs(ddg - (-9.0 * math.sin(2.1) + 2.0)) < 1e-6    # truncation ~8e-8, rounding ~6e-8


# ---- an exception in a callable ----------------------------------------------------------

def test_an_exception_in_a_callable_ends_the_run_with_its_message_and_the_results_so_far():
    def law(t, l, ldot):
        if t > 0.3:
            raise ValueError("the measured table ends at 0.3 s")
        return K * (l - L0) + C * ldot

    with pytest.raises(flexmbd.SolverFailure) as failure:
        _slider(law).run()
    message = str(failure.value)
    for words in ("force 'spring'", "the user spring law raised ValueError: the measured table ends at 0.3 s",
                  "at t = 0.3"):
        assert words in message, message
    rows = failure.value.results
    assert not rows.ok
    assert 0.29 - 1e-12 <= rows.t[-1] <= 0.3 + 1e-12  # every output before the failure
    assert failure.value.time == rows.t[-1]
    # the same without raising
    res = _slider(law).run(raise_on_failure=False)
    assert not res.ok and "ValueError" in res.message and len(res) == len(rows)


def test_a_torque_law_that_returns_no_number_names_what_it_returned():
    with pytest.raises(flexmbd.SolverFailure, match=r"force 'motor': the user time law raised TypeError: it "
                                                    r"returned 'x', not a number at t = 0"):
        _python_pendulum(lambda t: "x").run()


def test_arguments_are_checked_with_words():
    with pytest.raises(TypeError, match="user_law: f must be a callable f\\(t\\), got 3"):
        flexmbd.user_law(3)
    with pytest.raises(TypeError, match="spring_law: derivative must be a callable"):
        flexmbd.spring_law(lambda t, x, v: 0.0, derivative="k")
    sys_ = flexmbd.Scene("x").system
    a = sys_.add_rigid_body("a", flexmbd.RigidBodyProperties(1.0, 0.1))
    with pytest.raises(flexmbd.InputError, match="add_spring_damper: both a law and stiffness/damping given"):
        sys_.add_spring_damper("s", "ground", (0, 0), a, (0, 0), 10.0, 0.0, 0.0, law=lambda t, x, v: 0.0)
    with pytest.raises(TypeError, match="add_applied_load: torque must be a time law"):
        sys_.add_applied_load("f", a, (0, 0), torque=3.0)


def test_runs_with_python_laws_go_on_in_threads():
    # the GIL is released during the run and taken only inside the callable: two runs in
    # threads and the main thread all make progress and the runs give the serial numbers
    law = lambda t: 0.0 + A * math.sin(W * t + 0.0)  # noqa: E731
    serial = _python_pendulum(law).run().data
    results = [None, None]

    def work(k):
        results[k] = _python_pendulum(law).run().data

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for r in results:
        assert np.array_equal(r, serial)


def test_spatial_torsion_law_follows_the_closed_form():
    # a disc on a spatial revolute joint about z with tau = k theta + c theta' (a Python
    # law), started at theta = 0 with angular velocity w0: theta = e^(-zeta wn t) (w0/wd) sin(wd t)
    J, k, c, w0 = 0.4, 20.0, 0.1, 1.5
    scene = flexmbd.Scene("torsion")
    sys_ = scene.system
    disc = sys_.add_rigid_body_3d("disc", flexmbd.RigidBody3dProperties(mass=3.0, inertia=(0.3, 0.35, J)),
                                  flexmbd.FrameState3d(angular_velocity=(0, 0, w0)))
    hinge = sys_.add_spatial_joint_at_world("hinge", "revolute", "ground", disc, (0, 0, 0), axis=(0, 0, 1))
    sys_.add_spatial_rotational_spring_damper("torsion", hinge, free_angle=0.0,
                                              law=lambda t, th, thdot: k * th + c * thdot)
    scene.solver.t_end = 2.0
    res = scene.run()
    wn = math.sqrt(k / J)
    zeta = c / (2.0 * math.sqrt(k * J))
    wd = wn * math.sqrt(1.0 - zeta * zeta)
    exact = np.exp(-zeta * wn * res.t) * (w0 / wd) * np.sin(wd * res.t)
    error = np.max(np.abs(res["hinge.angle"] - exact))
    assert error < 1e-5, error  # amplitude ~0.21 rad over ~2.3 periods; as for the slider


def test_ctrl_c_inside_a_callable_interrupts_the_run():
    # KeyboardInterrupt raised while a callable runs (Ctrl-C then) ends the run as Ctrl-C
    # between calls does: KeyboardInterrupt in Python, not a solver failure
    def torque(t):
        if t > 0.2:
            raise KeyboardInterrupt
        return 1.0

    with pytest.raises(KeyboardInterrupt):
        _python_pendulum(torque).run()
    assert _python_pendulum(lambda t: 1.0).run().ok  # the interpreter and the next run are fine


def test_spatial_python_torque_and_driver_laws_equal_the_scene_laws_bit_for_bit():
    # a spatial disc on a hinge with a torque about z, and a driven hinge: a Python callable
    # against the same built-in law (the operations of core/time_law.cpp)
    def disc(torque):
        scene = flexmbd.Scene("disc")
        sys_ = scene.system
        d = sys_.add_rigid_body_3d("disc", flexmbd.RigidBody3dProperties(mass=3.0, inertia=(0.3, 0.35, 0.4)),
                                   flexmbd.FrameState3d())
        sys_.add_spatial_joint_at_world("hinge", "revolute", "ground", d, (0, 0, 0), axis=(0, 0, 1))
        sys_.add_spatial_applied_load("motor", d, torque_z=torque)
        scene.solver.t_end = 0.5
        return scene.run()

    assert np.array_equal(disc(lambda t: 0.0 + A * math.sin(W * t + 0.0)).data, disc(flexmbd.harmonic_law(A, W)).data)

    def driven(law):
        scene = flexmbd.Scene("arm")
        sys_ = scene.system
        arm = sys_.add_rigid_body_3d("arm", flexmbd.RigidBody3dProperties(mass=2.0, inertia=(0.01, 0.02, 0.03)),
                                     flexmbd.FrameState3d(position=(0.5, 0, 1)))
        hinge = sys_.add_spatial_joint_at_world("hinge", "revolute", "ground", arm, (0, 0, 1), axis=(0, 0, 1))
        sys_.add_joint_angle_driver("motor", hinge, law)
        scene.solver.t_end = 0.5
        return scene.run()

    assert np.array_equal(driven(flexmbd.user_law(lambda t: 0.0 + 2.0 * t, lambda t: 2.0, lambda t: 0.0)).data,
                          driven(flexmbd.constant_speed_law(2.0)).data)

"""Closed form of the centred slider-crank with a rigid rod, shared by the scripts
(print_table.py, demo_report.py, plot_kinematics.py); the C++ tests and benchmarks use
the same formulas from problems/reference_solutions.hpp.

Crank l1, rod l2, crank angle a (source document 000, eqs. 30-32, for a' = 1, a'' = 0):
  x      = l1 cos a + sqrt(l2^2 - l1^2 sin^2 a)
  dx/da  = -l1 sin a - l1^2 sin a cos a / r                    (r = sqrt(l2^2 - l1^2 sin^2 a))
  d2x/da2 = -l1 cos a - l1^2 (l1^2 sin^4 a + l2^2 cos 2a) / r^3
Standard library only.
"""
import math


def slider_x(l1, l2, a):
    """Slider position (eq. 30)."""
    s = l1 * math.sin(a)
    return l1 * math.cos(a) + math.sqrt(l2 * l2 - s * s)


def slider_dx_da(l1, l2, a):
    """First derivative by the crank angle (eq. 31): the velocity at a' = 1."""
    s, c = math.sin(a), math.cos(a)
    r = math.sqrt(l2 * l2 - l1 * l1 * s * s)
    return -l1 * s - l1 * l1 * s * c / r


def slider_d2x_da2(l1, l2, a):
    """Second derivative by the crank angle (eq. 32): the acceleration at a' = 1, a'' = 0."""
    s = math.sin(a)
    r = math.sqrt(l2 * l2 - l1 * l1 * s * s)
    return -l1 * math.cos(a) - l1 * l1 * (l1 * l1 * s ** 4 + l2 * l2 * math.cos(2 * a)) / r ** 3

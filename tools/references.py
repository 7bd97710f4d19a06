"""Correlations of docs/reference.md (taken from the project's reference notes, cited there),
shared by the validation tools."""
import numpy as np


# Correlations of docs/reference.md (mean void fraction against a).
def benyahia(a): return 0.390 + 1.740 / (a + 1.140) ** 2
def jeschar(a): return 0.375 + 0.34 / a
def zou_yu_dense(a): return 0.372 + 0.002 * (np.exp(15.306 / a) - 1)
def zou_yu_loose(a): return 0.400 + 0.010 * (np.exp(10.686 / a) - 1)


def dixon(a):
    x = 1.0 / np.asarray(a, dtype=float)
    return np.where(x <= 0.5, 0.4 + 0.05 * x + 0.412 * x * x, 0.528 + 2.464 * (x - 0.5))


def de_klerk(z, eps_b):
    z = np.asarray(z, dtype=float)
    return np.where(z <= 0.637, 2.14 * z * z - 2.53 * z + 1,
                    eps_b + 0.29 * np.exp(-0.6 * z) * np.cos(2.3 * np.pi * (z - 0.16)) + 0.15 * np.exp(-0.9 * z))

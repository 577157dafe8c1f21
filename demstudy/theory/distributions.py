"""Reference distributions: Campbell's folded Maxwellians for X1...X5, Malik's scaled Gaussian,
and the Savage-Jeffrey 2D collision-angle distribution.

Campbell (1982) scales each fluctuation by its rms, X = |q - <q>| / sqrt(<q'^2>), and
histograms X on [0, inf). For k Gaussian degrees of freedom X follows the chi density in the
scaling <X^2> = 1, P_k(X) = 2 a^(k/2) / Gamma(k/2) X^(k-1) exp(-a X^2) with a = k/2:

* X1, X2, X3 (u, v, omega; k = 1, a = 1/2): P = 2 sqrt(a/pi) exp(-a X^2), the **folded**
  form. The thesis prints sqrt(a/pi) exp(-a X^2) (L1297-1329), which integrates to 1/2 on
  [0, inf); with a = 1/2 only the folded form is consistent with <X^2> = 1
  (``folded=False`` returns the printed form for comparison).
* X4 (u, v together; k = 2, a = 1): P = 2 a X exp(-a X^2).
* X5 (u, v, sqrt(beta) omega; k = 3, a = 3/2): P = 4 sqrt(a^3/pi) X^2 exp(-a X^2).

Malik (2008) scales each component C by its standard deviation sigma and the histogram so
that P(0) = 1: the Gaussian reference is exp(-x^2/2).

Savage & Jeffrey (1981), 2D discs: the angle theta of the line of centres at contact,
measured from the flow direction on [0, pi), has
P(theta) = (1/pi) erfc(S cos(theta) sin(theta) / sqrt(2)) (standard erfc; the thesis's
printed erfc definition omits 2/sqrt(pi)), with S = 2R (du/dy) / sqrt(<u'^2>). P is
symmetric under theta -> pi/2 - theta, so Campbell's text and listing angle conventions
(theta_code = 90 deg - theta_text) give the same prediction. The "corrected length scale"
replaces a length in S by the mean spacing C = R sqrt(pi/nu): see :func:`corrected_s`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import erfc, gammaln

__all__ = [
    "CAMPBELL_A",
    "CAMPBELL_DOF",
    "campbell_reference",
    "chi_density",
    "corrected_s",
    "malik_gaussian",
    "savage_jeffrey",
]

CAMPBELL_DOF = {1: 1, 2: 1, 3: 1, 4: 2, 5: 3}
"""Degrees of freedom behind X1...X5 (2D discs: u, v, omega, (u, v), (u, v, omega))."""
CAMPBELL_A = {i: k / 2 for i, k in CAMPBELL_DOF.items()}
"""a_i = 1/2, 1/2, 1/2, 1, 3/2 from the consistency condition <X^2> = 1."""


def chi_density(x: ArrayLike, k: int) -> np.ndarray:
    """Chi density of k Gaussian degrees of freedom scaled to <X^2> = 1 (X >= 0; 0 below)."""
    if k < 1:
        raise ValueError(f"k must be >= 1, got {k!r}")
    x = np.asarray(x, float)
    a = k / 2
    xp = np.maximum(x, 0.0)
    log = math.log(2.0) + a * math.log(a) - gammaln(a) - a * xp**2
    return np.where(x >= 0, np.exp(log) * xp ** (k - 1), 0.0)


def campbell_reference(x: ArrayLike, i: int, folded: bool = True) -> np.ndarray:
    """Campbell's Maxwellian reference P_i(X) for X_i (i = 1...5), explicit forms above."""
    if i not in CAMPBELL_A:
        raise ValueError(f"i must be 1...5, got {i!r}")
    x = np.asarray(x, float)
    a = CAMPBELL_A[i]
    e = np.exp(-a * x**2)
    if i <= 3:
        p = (2.0 if folded else 1.0) * math.sqrt(a / math.pi) * e
    elif i == 4:
        p = 2 * a * x * e
    else:
        p = 4 * math.sqrt(a**3 / math.pi) * x**2 * e
    return np.where(x >= 0, p, 0.0)


def malik_gaussian(x: ArrayLike) -> np.ndarray:
    """Malik's reference: C / sigma on the axis, P(0) = 1, i.e. exp(-x^2/2)."""
    x = np.asarray(x, float)
    return np.exp(-0.5 * x**2)


def corrected_s(s: ArrayLike, nu: ArrayLike, variant: str = "text") -> np.ndarray:
    """Savage-Jeffrey S with the mean spacing C = R sqrt(pi/nu) as length scale.

    ``variant="text"``: R replaced by C in S = 2R (du/dy)/sqrt(<u'^2>) (thesis L1372-1384),
    S' = S C / R = S sqrt(pi/nu). ``variant="listing"``: the listing's QRH = 0.5 S sqrt(pi/nu)
    = S C / (2R), i.e. the diameter 2R replaced by C.
    """
    factor = {"text": 1.0, "listing": 0.5}.get(variant)
    if factor is None:
        raise ValueError(f"variant must be 'text' or 'listing', got {variant!r}")
    return factor * np.asarray(s, float) * np.sqrt(np.pi / np.asarray(nu, float))


def savage_jeffrey(
    theta: ArrayLike, s: float, nu: float | None = None, length: str = "R"
) -> np.ndarray:
    """P(theta) = (1/pi) erfc(S' cos(theta) sin(theta) / sqrt 2), theta in radians on [0, pi).

    ``length="R"`` uses S itself; ``length="C"`` (needs ``nu``) uses
    S' = corrected_s(S, nu, "text") and ``length="C/2"`` the listing's variant. Normalised:
    the integral over [0, pi) is 1 for every S (erfc(x) + erfc(-x) = 2).
    """
    if length == "R":
        s_eff = s
    elif length in ("C", "C/2"):
        if nu is None:
            raise ValueError("length='C' needs the solid fraction nu")
        s_eff = float(corrected_s(s, nu, "text" if length == "C" else "listing"))
    else:
        raise ValueError(f"length must be 'R', 'C' or 'C/2', got {length!r}")
    theta = np.asarray(theta, float)
    return erfc(s_eff * np.cos(theta) * np.sin(theta) / math.sqrt(2)) / math.pi

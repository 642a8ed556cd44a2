"""Whether points follow one power law y = c x^α: the local exponent between neighbouring
points, and the χ² of the best single power law through them (a test, not a fit to draw).
``x`` float64[K] increasing, ``mean`` and ``error`` float64[K]: means of independent samples
and their standard errors."""

import numpy as np
from scipy import stats


def local_exponents(x, mean, error):
    """d ln y / d ln x between neighbouring points, at their geometric midpoints, with its
    error from the relative errors of the two means in quadrature. Returns (midpoints
    float64[K − 1], exponents, errors)."""
    x, mean, error = (np.asarray(a, dtype=float) for a in (x, mean, error))
    step = np.log(x[1:] / x[:-1])
    relative = error / mean
    return (np.sqrt(x[1:] * x[:-1]), np.log(mean[1:] / mean[:-1]) / step,
            np.hypot(relative[1:], relative[:-1]) / step)


def single_power_law(x, mean, error):
    """The weighted least-squares line ln y = ln c + α ln x (weights (y/δy)², the errors of
    ln y) and its goodness: (α, its standard error, χ², degrees of freedom K − 2, the
    probability of a χ² at least as large if one power law held)."""
    x, mean, error = (np.asarray(a, dtype=float) for a in (x, mean, error))
    u, v, weight = np.log(x), np.log(mean), (mean / error) ** 2
    (slope, intercept), covariance = np.polyfit(u, v, 1, w=np.sqrt(weight), cov="unscaled")
    chi_square = float(np.sum(weight * (v - intercept - slope * u) ** 2))
    freedom = x.size - 2
    return (float(slope), float(np.sqrt(covariance[0, 0])), chi_square, freedom,
            float(stats.chi2.sf(chi_square, freedom)))

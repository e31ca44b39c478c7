"""Independent references for the gravity tests (not a test module).

* :func:`pysh_acceleration`: pyshtools' ``MakeGravGridPoint`` (Holmes–Featherstone
  recursion in spherical coordinates, Fortran), converted to Cartesian components. It
  stops the Python process (Fortran STOP in ``PlmBar_d1``) at latitude exactly ±90°, so
  callers never pass the poles.
* :func:`pysh_potential`: ``pyshtools.expand.MakeGridPoint`` on coefficients scaled by
  (R/r)ⁿ, times μ/r.
* :func:`mp_potential`: a direct sum in mpmath (any precision) with the normalised
  column recursion in t = sin φ on P̄_nm/uᵐ (u = cos φ), multiplied by Re/Im of
  ((x + iy)/r)ᵐ, so that no division by u occurs and the poles are ordinary points; mpmath
  has no exponent range limits, so nothing under- or overflows. Derivatives come from
  :func:`mp_gradient` / :func:`mp_hessian` (central differences in mpmath).
"""

from __future__ import annotations

import mpmath as mp
import numpy as np

from gmuk.gravity import MOON_MU, MOON_RADIUS, SphericalHarmonicField, field_path

#: The gravity files shipped in the package (``gmuk/gravity/data``).
GRAIL_FILE = field_path("GRGM660PRIM")
EGM_FILE = field_path("EGM2008")


def kaula_field(N, seed=0, amplitude=1e-5, mu=MOON_MU, radius=MOON_RADIUS):
    """Synthetic field with C̄, S̄ ~ N(0, (amplitude/n²)²) for 2 ≤ n ≤ N, C̄₀₀ = 1."""
    rng = np.random.default_rng(seed)
    C = np.zeros((N + 1, N + 1))
    S = np.zeros((N + 1, N + 1))
    n, m = np.tril_indices(N + 1)
    keep = n >= 2
    sd = amplitude / np.maximum(n[keep], 1) ** 2
    C[n[keep], m[keep]] = rng.normal(0.0, sd)
    S[n[keep], m[keep]] = np.where(m[keep] > 0, rng.normal(0.0, sd), 0.0)
    C[0, 0] = 1.0
    return SphericalHarmonicField(mu, radius, C, S, name=f"Kaula-{N}-{seed}")


def spherical(r):
    """(|r|, latitude deg, longitude deg) of a Cartesian point."""
    x, y, z = r
    rn = float(np.sqrt(x * x + y * y + z * z))
    return rn, float(np.degrees(np.arcsin(z / rn))), float(np.degrees(np.arctan2(y, x)))


def point(radius, lat_deg, lon_deg):
    """Cartesian point from radius (m), latitude and longitude (degrees)."""
    la, lo = np.radians(lat_deg), np.radians(lon_deg)
    return radius * np.array([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)])


def pysh_acceleration(field, r):
    """pyshtools' gravity vector at r, in Cartesian components (m/s²)."""
    import pyshtools as pysh

    rn, lat, lon = spherical(r)
    assert abs(lat) < 90.0, "pyshtools stops the process at the poles"
    cilm = np.array([field.C, field.S])
    g_r, g_th, g_ph = pysh.gravmag.MakeGravGridPoint(cilm, field.mu, field.radius, rn, lat, lon)
    th, ph = np.radians(90.0 - lat), np.radians(lon)
    e_r = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
    e_th = np.array([np.cos(th) * np.cos(ph), np.cos(th) * np.sin(ph), -np.sin(th)])
    e_ph = np.array([-np.sin(ph), np.cos(ph), 0.0])
    return g_r * e_r + g_th * e_th + g_ph * e_ph


def pysh_potential(field, r):
    """U at r from pyshtools' MakeGridPoint on (R/r)ⁿ-scaled coefficients (m²/s²)."""
    import pyshtools as pysh

    rn, lat, lon = spherical(r)
    scale = (field.radius / rn) ** np.arange(field.degree + 1)
    cilm = np.array([field.C, field.S]) * scale[None, :, None]
    return field.mu / rn * pysh.expand.MakeGridPoint(cilm, lat, lon)


class MpField:
    """A field's coefficients and recursion factors in mpmath, for direct sums.

    Parameters
    ----------
    field : SphericalHarmonicField
    orders : iterable of int, optional
        The orders m summed (default: all). Near a pole, order m contributes
        ``O((n cos φ)ᵐ / m!)``, so a few orders suffice there.
    dps : int
        mpmath precision (decimal digits).
    central : bool
        ``False`` drops C̄₀₀ (the perturbation only, computed without cancellation).
    """

    def __init__(self, field, orders=None, dps=60, central=True):
        self.dps = dps
        with mp.workdps(dps):
            self.N = field.degree
            self.orders = sorted(range(self.N + 1) if orders is None else set(orders))
            self.mu = mp.mpf(field.mu)
            self.R = mp.mpf(field.radius)
            self.C = {}
            self.S = {}
            self.a = {}
            self.b = {}
            for m in self.orders:
                for n in range(m, self.N + 1):
                    self.C[n, m] = mp.mpf(float(field.C[n, m]))
                    self.S[n, m] = mp.mpf(float(field.S[n, m]))
                    if n > m:
                        self.a[n, m] = mp.sqrt(
                            mp.mpf((2 * n - 1) * (2 * n + 1)) / ((n - m) * (n + m))
                        )
                    if n >= m + 2:
                        self.b[n, m] = mp.sqrt(
                            mp.mpf((2 * n + 1) * (n + m - 1) * (n - m - 1))
                            / ((n - m) * (n + m) * (2 * n - 3))
                        )
            if not central and 0 in self.orders:
                self.C[0, 0] = mp.mpf(0)
            # P̄_mm / uᵐ = √3 ∏_{k=2..m} √((2k+1)/(2k))
            self.seed = {}
            s = mp.mpf(1)
            for m in range(max(self.orders) + 1):
                if m == 1:
                    s *= mp.sqrt(3)
                elif m > 1:
                    s *= mp.sqrt(mp.mpf(2 * m + 1) / (2 * m))
                self.seed[m] = s


def mp_potential(mf, x, y, z):
    """U(x, y, z) (mpmath numbers, m) by direct summation over the orders of ``mf``."""
    with mp.workdps(mf.dps):
        r = mp.sqrt(x * x + y * y + z * z)
        t = z / r
        w = mp.mpc(x, y) / r  # u e^{iλ}
        rho = mf.R / r
        total = mp.mpf(0)
        for m in mf.orders:
            wm = w**m
            p2 = mp.mpf(0)
            p1 = mf.seed[m]
            rho_n = rho**m
            col_c = mp.mpf(0)
            col_s = mp.mpf(0)
            for n in range(m, mf.N + 1):
                if n > m:
                    p = mf.a[n, m] * t * p1 - (mf.b[n, m] * p2 if n >= m + 2 else 0)
                    p2, p1 = p1, p
                    rho_n *= rho
                col_c += rho_n * mf.C[n, m] * p1
                col_s += rho_n * mf.S[n, m] * p1
            total += col_c * wm.real + col_s * wm.imag
        return mf.mu / r * total


def mp_gradient(mf, r, h_rel=1e-15):
    """Central-difference gradient of :func:`mp_potential` at r (float (3,)), as floats."""
    with mp.workdps(mf.dps):
        p = [mp.mpf(float(v)) for v in r]
        h = mp.mpf(h_rel) * mp.sqrt(sum(v * v for v in p))
        g = []
        for i in range(3):
            pp, pm = list(p), list(p)
            pp[i] += h
            pm[i] -= h
            g.append((mp_potential(mf, *pp) - mp_potential(mf, *pm)) / (2 * h))
        return np.array([float(v) for v in g])


def mp_hessian(mf, r, h_rel=1e-15):
    """Central-difference Hessian of :func:`mp_potential` at r, as floats (3, 3)."""
    with mp.workdps(mf.dps):
        p = [mp.mpf(float(v)) for v in r]
        h = mp.mpf(h_rel) * mp.sqrt(sum(v * v for v in p))
        U0 = mp_potential(mf, *p)

        def U(di, dj=None, si=1, sj=1):
            q = list(p)
            q[di] += si * h
            if dj is not None:
                q[dj] += sj * h
            return mp_potential(mf, *q)

        H = [[mp.mpf(0)] * 3 for _ in range(3)]
        for i in range(3):
            H[i][i] = (U(i) - 2 * U0 + U(i, si=-1)) / h**2
            for j in range(i + 1, 3):
                v = (U(i, j, 1, 1) - U(i, j, 1, -1) - U(i, j, -1, 1) + U(i, j, -1, -1)) / (4 * h**2)
                H[i][j] = H[j][i] = v
        return np.array([[float(v) for v in row] for row in H])

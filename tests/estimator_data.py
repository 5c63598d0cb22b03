"""A fast synthetic stand-in for a simulated database, for unit tests of the estimator.

SAs are mesh harmonics + grade-scaled random content at other orders (the tooth-profile
errors) + a local fault impulse growing with y. Real simulator data are used in the
integration tests; this only exercises the estimator's mechanics.
"""

import numpy as np
import xarray as xr

N = 2048
MESH = 38


def synthetic_sa(y, grade, rng, *, same_gear=False):
    """SAs of fault sizes ``y``; each its own gear unless ``same_gear`` (one profile draw)."""
    y = np.atleast_1d(np.asarray(y, float))
    theta = np.arange(N) / N
    mesh = 100 * np.cos(2 * np.pi * MESH * theta) + 40 * np.cos(4 * np.pi * MESH * theta + 1)
    n_gears = 1 if same_gear else y.size
    spec = np.zeros((n_gears, N // 2 + 1), complex)
    orders = np.arange(1, 400)
    spec[:, orders] = (rng.normal(size=(n_gears, orders.size))
                       + 1j * rng.normal(size=(n_gears, orders.size))) / orders ** 0.5
    profile = np.fft.irfft(spec, n=N) * N * 0.3 * grade
    width = 3.0 + 10 * y[:, None]
    pulse = 80 * y[:, None] ** 1.5 * np.exp(-0.5 * ((np.arange(N) - 1000) / width) ** 2)
    ring = pulse * np.cos(2 * np.pi * 300 * theta)
    return mesh + profile + ring


def synthetic_database(grades=(3, 6, 9), n_healthy=20, n_faulty=80, seed=0):
    rng = np.random.default_rng(seed)
    sas, ys, gs = [], [], []
    for g in grades:
        y = np.r_[np.zeros(n_healthy), rng.uniform(0, 1, n_faulty)]
        sas.append(synthetic_sa(y, g, rng))
        ys.append(y)
        gs.append(np.full(y.size, g))
    return xr.Dataset({"sa": (("signal", "angle"), np.vstack(sas))},
                      coords={"fault_size": ("signal", np.concatenate(ys)),
                              "grade": ("signal", np.concatenate(gs))})


def paired_synthetic_database(grades=(3, 6, 9), n_healthy=20, n_faulty=80, seed=0):
    """``synthetic_database``'s layout with ``sa_twin``: each signal's own gear, healthy
    (the profile content drawn from the signal's own seed, as the simulator's database)."""
    rng = np.random.default_rng(seed)
    sas, twins, ys, gs = [], [], [], []
    for g in grades:
        y = np.r_[np.zeros(n_healthy), rng.uniform(0, 1, n_faulty)]
        seeds = rng.integers(0, 2**31, y.size)
        sas += [synthetic_sa([yi], g, np.random.default_rng(s))[0] for yi, s in zip(y, seeds)]
        twins += [synthetic_sa([0.0], g, np.random.default_rng(s))[0] for s in seeds]
        ys.append(y)
        gs.append(np.full(y.size, g))
    return xr.Dataset({"sa": (("signal", "angle"), np.vstack(sas)),
                       "sa_twin": (("signal", "angle"), np.vstack(twins))},
                      coords={"fault_size": ("signal", np.concatenate(ys)),
                              "grade": ("signal", np.concatenate(gs))})


def synthetic_target(grade, tf, *, sizes=(0.32, 0.56, 0.66), n_healthy=30, n_each=15,
                     noise=0.5, seed=1):
    """Target-domain data through ``tf``: healthy SAs, long healthy, example, test set."""
    from gearshot.transfer import propagate

    rng = np.random.default_rng(seed)
    y = np.r_[np.zeros(n_healthy + 1), np.repeat(sizes, n_each)]
    clean = synthetic_sa(y, grade, np.random.default_rng(seed + 100), same_gear=True)
    noisy = clean + noise * rng.normal(size=clean.shape)
    long = clean[n_healthy] + noise * 7 * rng.normal(size=(128, N))  # 50-cycle SAs: /7
    return (propagate(noisy[:n_healthy], tf), propagate(long, tf).ravel(),
            propagate(noisy[n_healthy + 1:], tf), y[n_healthy + 1:])


def tf_pair():
    """A resonant target path and a different one held out for selection, on the SA grid."""
    from gearshot.transfer import resample_transfer_function

    f = np.linspace(0, 1, 513)
    path = 0.3 / (1 - (f / 0.3) ** 2 + 0.1j * f / 0.3) + 0.05
    held_out = 0.5 / (1 - (f / 0.6) ** 2 + 0.2j * f / 0.6) + 0.1
    return resample_transfer_function(path, N), resample_transfer_function(held_out, N)

"""Bad input raises GearshotError naming the parameter; nothing else escapes."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from gearshot import GearshotError, features, signal, transfer

N = 256


def test_error_type_is_a_value_error():
    assert issubclass(GearshotError, ValueError)


@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: signal.synchronous_average([1.0, np.nan, 2.0, 3.0], 2), ["x", "nan"]),
        (lambda: signal.synchronous_average(np.ones(4), 2, n_cycles=3), ["n_cycles=3", "2"]),
        (lambda: signal.synchronous_average(np.ones(3), 4), ["x", "one cycle"]),
        (lambda: signal.synchronous_average([], 4), ["x", "empty"]),
        (lambda: signal.synchronous_average(np.ones(8), 0), ["samples_per_cycle", "0"]),
        (lambda: signal.difference_signal(np.ones(N), 128), ["mesh_order=128", "Nyquist"]),
        (lambda: signal.harmonic_signal(np.ones(N), 300), ["mesh_order=300"]),
        (lambda: signal.difference_signal(np.ones(N), 2.5), ["mesh_order", "2.5"]),
        (lambda: signal.envelope(np.full(8, np.inf)), ["x", "inf"]),
        (lambda: signal.amplitude_spectrum(np.ones(100), nfft=128), ["nfft=128", "100"]),
        (lambda: signal.acs_background(np.ones(100), segment_size=200), ["segment_size=200"]),
        (lambda: signal.acs_background(np.ones(300), overlap=1.0), ["overlap", "1.0"]),
        (lambda: signal.minimum_phase(np.zeros(64)), ["magnitude", "zero"]),
        (lambda: signal.pulse_times(np.ones((2, 10)), 1e3), ["tacho", "ndim=2"]),
        (lambda: signal.pulse_times(np.zeros(100), 1e3), ["tacho", "constant"]),
        (lambda: signal.pulse_times(np.r_[0, 1, 0, 0], -5.0), ["fs", "-5.0"]),
        (lambda: signal.angular_resample(np.ones(100), 100.0, [0.1], samples_per_rev=8),
         ["pulse_times", "2 pulses"]),
        (lambda: signal.angular_resample(np.ones(100), 100.0, [0.5, 0.2, 0.8],
                                         samples_per_rev=8), ["pulse_times", "increasing"]),
        (lambda: signal.angular_resample(np.ones(100), 100.0, [0.1, 5.0], samples_per_rev=8),
         ["pulse_times", "fs"]),
        (lambda: signal.subtract_healthy(np.ones((2, 64)), np.ones((2, 32))),
         ["healthy_refs", "32"]),
        (lambda: signal.subtract_healthy(np.ones(64), np.ones(64), upsample=0),
         ["upsample", "0"]),
        (lambda: features.extract_features(np.ones((2, N)), 38, names=["rms_diff", "bogus"]),
         ["bogus", "rms_diff", "kurtosis_diff", "na4"]),
        (lambda: features.extract_features(np.ones((2, N)), 200), ["mesh_order=200"]),
        (lambda: transfer.propagate(np.ones((2, 64)), np.ones(32)), ["tf", "32", "64"]),
        (lambda: transfer.resample_transfer_function([1.0], 64), ["tf_one_sided"]),
        (lambda: transfer.rms_normalize(np.ones(8), np.zeros(8)), ["reference", "zero"]),
        (lambda: transfer.estimate_transfer_function(np.ones(1000), 2048), ["x", "nfft"]),
    ],
)
def test_bad_input_names_parameter_and_value(call, words):
    with pytest.raises(GearshotError) as info:
        call()
    message = str(info.value).lower()
    for word in words:
        assert word.lower() in message, f"{word!r} not in {message!r}"


# --- property tests: arbitrary arrays never raise anything but GearshotError ---------

floats = st.floats(allow_nan=True, allow_infinity=True, width=64)
arrays = hnp.arrays(
    dtype=np.float64,
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=40),
    elements=floats,
)
small_ints = st.integers(min_value=-3, max_value=70)

FUNCTIONS = [
    lambda x, k: signal.synchronous_average(x, k),
    lambda x, k: signal.synchronous_average(x, 4, n_cycles=k),
    lambda x, k: signal.difference_signal(x, k),
    lambda x, k: signal.harmonic_signal(x, k, n_sidebands=2),
    lambda x, k: signal.envelope(x),
    lambda x, k: signal.amplitude_spectrum(x, nfft=k),
    lambda x, k: signal.acs_background(x, segment_size=k),
    lambda x, k: signal.minimum_phase(x),
    lambda x, k: signal.pulse_times(x, 1000.0),
    lambda x, k: signal.angular_resample(np.ones(64), 8.0, x, samples_per_rev=k),
    lambda x, k: signal.subtract_healthy(x, x, upsample=k),
    lambda x, k: signal.fractional_shift(x, k / 3),
    lambda x, k: features.extract_features(x, k),
    lambda x, k: transfer.propagate(x, np.ones(k if k > 0 else 1)),
    lambda x, k: transfer.resample_transfer_function(x, k),
    lambda x, k: transfer.rms_normalize(x, x),
]


@pytest.mark.parametrize("func", FUNCTIONS, ids=range(len(FUNCTIONS)))
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(x=arrays, k=small_ints)
def test_only_gearshot_errors_escape(func, x, k):
    try:
        with np.errstate(all="ignore"):
            func(x, k)
    except GearshotError:
        pass

"""``estimator="paper"`` gives the predictions of the estimator before ``estimator`` existed,
bit for bit.

The reference file ``tests/data/paper_estimator_predictions.npz`` was written by the code of
commit 97efe7c (before issue #30); regenerate it only from such a tree::

    git archive 97efe7c src tests | tar -x -C /tmp/before
    cd /tmp/before && PYTHONPATH=src:tests python \
        <this tree>/tests/test_estimator_paper_identity.py \
        <this tree>/tests/data/paper_estimator_predictions.npz
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

REFERENCE = Path(__file__).parent / "data" / "paper_estimator_predictions.npz"
CASES = {"grade": dict(calibration="grade"), "tuned": dict(calibration="tuned"),
         "joint": dict(calibration="joint")}


def _predictions(**extra):
    from estimator_data import paired_synthetic_database, synthetic_target, tf_pair

    from gearshot.estimator import OneFaultShotEstimator

    tfs = tf_pair()
    db = paired_synthetic_database(n_healthy=10, n_faulty=40)
    healthy, long, faulty, y = synthetic_target(6, tfs[0], n_healthy=10, n_each=5)
    out = {}
    for name, params in CASES.items():
        est = OneFaultShotEstimator(nominal_grade=3, grades=[3, 6, 9], random_state=0,
                                    **params, **extra)
        est.fit(db, healthy, faulty[7], y[7], long, selection_tf=tfs[1])
        low, high = est.predict_interval(faulty)
        out[f"{name}/predict"] = est.predict(faulty)
        out[f"{name}/low"], out[f"{name}/high"] = low, high
    return out


@pytest.mark.skipif(not REFERENCE.exists(), reason="reference file missing")
def test_paper_estimator_reproduces_the_predictions_before_issue_30():
    reference = dict(np.load(REFERENCE))
    now = _predictions(estimator="paper")
    assert set(now) == set(reference)
    for key, value in reference.items():
        np.testing.assert_array_equal(now[key], value, err_msg=key)


@pytest.mark.skipif(not REFERENCE.exists(), reason="reference file missing")
def test_another_regressor_gives_other_predictions():
    reference = dict(np.load(REFERENCE))
    other = _predictions(estimator="boosting")
    assert not np.array_equal(other["tuned/predict"], reference["tuned/predict"])


if __name__ == "__main__":
    np.savez(sys.argv[1], **_predictions())

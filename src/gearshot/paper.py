"""The constants of Matania et al., *Adv. Eng. Informatics* 56 (2023) 101945, said once.

Every default that stands for "the paper's set-up" (the gear pair of the test rig, the
fault sizes of Table 1, the operating grid of the simulated database) reads this module,
so a change of set-up is one line here.

Examples
--------
>>> from gearshot import paper
>>> paper.PINION_TEETH, paper.GEAR_TEETH
(17, 38)
>>> paper.TABLE1_SIZES
(0.32, 0.56, 0.66)
>>> len(paper.PAPER_SPEEDS) * len(paper.PAPER_LOADS)    # the operating conditions
104
"""

from __future__ import annotations

__all__ = [
    "PINION_TEETH", "GEAR_TEETH", "MODULE", "FACE_WIDTH", "PRESSURE_ANGLE_DEG",
    "TABLE1_SIZES", "PAPER_SPEEDS", "PAPER_LOADS", "SAMPLES_PER_CYCLE",
    "CYCLES_PER_SEGMENT",
    "RIG_CONDITIONS", "RIG_SPEED", "RIG_LOAD", "RIG_HEALTHY_RECORDINGS", "RIG_REPETITIONS",
    "RIG_DURATION",
]

#: Teeth of the driving pinion (input shaft, where the tacho sits).
PINION_TEETH: int = 17
#: Teeth of the driven gear, the faulty wheel; one revolution of it is the SA cycle, so it
#: is also the gear-mesh order of the paper's SAs.
GEAR_TEETH: int = 38
#: Module of the pair, m.
MODULE: float = 3e-3
#: Face width, m.
FACE_WIDTH: float = 15e-3
#: Pressure angle, degrees.
PRESSURE_ANGLE_DEG: float = 20.0

#: FTFF sizes of the rig experiments (Table 1, Sec. 4.2).
TABLE1_SIZES: tuple[float, ...] = (0.32, 0.56, 0.66)
#: Input-shaft speeds of the simulated database, rev/s (10 ... 35, step 1).
PAPER_SPEEDS: tuple[float, ...] = tuple(float(s) for s in range(10, 36))
#: Output load torques of the simulated database, N m.
PAPER_LOADS: tuple[float, ...] = (5.0, 10.0, 15.0, 20.0)

#: Points per SA cycle (one gear revolution).
SAMPLES_PER_CYCLE: int = 2048
#: Cycles averaged into one experimental SA segment.
CYCLES_PER_SEGMENT: int = 50

#: Operating conditions of the rig experiments (Sec. 4.2): (input speed rev/s, load N m).
RIG_CONDITIONS: tuple[tuple[float, float], ...] = ((15.0, 10.0), (15.0, 5.0), (30.0, 5.0),
                                                   (30.0, 10.0))
#: The condition a one-condition run (the demo, ``gearshot rig``, ``simulate``,
#: ``experiment``) defaults to: the first of :data:`RIG_CONDITIONS`.
RIG_SPEED, RIG_LOAD = RIG_CONDITIONS[0]
#: Table 1 per condition: healthy recordings, recordings per fault size, seconds each.
RIG_HEALTHY_RECORDINGS: int = 6
RIG_REPETITIONS: int = 6
RIG_DURATION: float = 60.0

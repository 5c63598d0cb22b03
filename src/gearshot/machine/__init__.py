"""Machine descriptions: gear train, shafts, tacho, sensors, file layout, monitored gear.

A :class:`Machine` says everything gearshot needs to turn a real recording into
synchronous averages of any shaft: which column of the file is which channel, how volts
become physical units, which shaft the tacho watches and with how many pulses per
revolution, and the tooth counts of every gear stage (so the speed ratio between any two
shafts is an exact fraction). It is read from a TOML file (:meth:`Machine.from_toml`)::

    name = "PHM09 gearbox, spur train"
    shafts = ["input", "idler", "output"]

    [[stage]]                      # one per gear mesh
    driver = "input"               # shaft of the driving gear
    driver_teeth = 32
    driven = "idler"
    driven_teeth = 96
    module_mm = 3.0                # optional geometry (defaults: the paper's pair)
    face_width_mm = 15.0
    pressure_angle_deg = 20.0
    helix_angle_deg = 0.0
    # helical = true               # helical teeth of unstated angle: not simulated

    [tacho]
    channel = "tacho"              # a name from [file].columns
    shaft = "input"
    pulses_per_rev = 10
    # threshold = 2.5              # optional trigger level, file units

    # No [tacho] table: the speed is estimated from the vibration (gearshot.signal.tracking)
    # [speed]                      # optional; used only when a recording has no tacho
    # shaft = "input"              # the shaft tracked (default: the first shaft)
    # range_hz = [26, 52]          # its speeds searched, rev/s (keep within an octave)
    # track = 32                   # optional: the order whose phase gives the angle
    # sensor = "acc_input"         # optional: the sensor tracked (default: the first)

    [[sensor]]                     # in order; the first is the default sensor
    name = "acc_input"
    channel = "acc_input"
    sensitivity = "10 mV/g"        # or a number (file units per `unit`) with unit = "g"
    ac_coupled = true              # remove the record's mean (sensor bias); default true

    [file]
    columns = ["acc_input", "acc_output", "tacho"]
    delimiter = "whitespace"       # or ",", ";", "tab"
    header = false
    fs = "200000/3"                # Hz: a number or an exact fraction "a/b"

    [monitored]
    shaft = "input"
    teeth = 32

    [analysis]                     # all optional
    samples_per_cycle = 2048
    cycles_per_segment = "all"     # or an integer
    shaft_orders = [1, 2]          # shaft orders removed for FM4, M6A, M8A, NA4, ER
    n_sidebands = 2
    antialias = true

Every error is a :class:`gearshot.GearshotError` naming the key and the bad value.

The package: :mod:`.parts` (the dataclasses of a machine's parts), :mod:`.gearbox`
(:class:`Machine`: the parts checked together, the gear train's exact speed ratios),
:mod:`.signal_check` (the machine file verified against recordings: its mesh orders where
it says, the tracked speed checked),
:mod:`._tables` (one parser per table of the file), :mod:`._consistency` (the checks across
parts, the speed-ratio solver), :mod:`._values` (single values and tables of a file).
"""

from __future__ import annotations

from ._values import parse_sensitivity
from .gearbox import Machine
from .parts import FileLayout, GearStage, MonitoredGear, Sensor, Tacho, VibrationSpeed

__all__ = ["Machine", "GearStage", "Tacho", "VibrationSpeed", "Sensor", "FileLayout",
           "MonitoredGear", "parse_sensitivity"]

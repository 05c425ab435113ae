"""`printgen calibrate`: material profiles from tensile-test exports.

reader (exports -> SI channels) -> specimen (dimensions) -> sample (curve and fits: fit,
compliance) -> pipeline (over samples: aggregate) -> profile_writer / plot / record.
"""

from printgen.calibrate.pipeline import Calibration, calibrate
from printgen.calibrate.reader import TestRecord, read_export
from printgen.calibrate.sample import FitOptions, SampleFit

__all__ = ["Calibration", "FitOptions", "SampleFit", "TestRecord", "calibrate", "read_export"]

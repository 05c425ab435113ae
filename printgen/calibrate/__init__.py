"""`printgen calibrate`: material profiles from tensile-test exports.

reader (exports -> SI channels) -> specimen (dimensions) -> sample (curve and fits: fit,
compliance) -> pipeline (over samples: aggregate) -> profile_writer / plot / record.
"""

import sys
import types
from typing import Any

from printgen.calibrate.pipeline import Calibration, calibrate
from printgen.calibrate.reader import TestRecord, read_export
from printgen.calibrate.sample import FitOptions, SampleFit
from printgen.calibrate.waved import WaveCalibration

__all__ = ["Calibration", "FitOptions", "SampleFit", "TestRecord", "WaveCalibration", "calibrate",
           "read_export"]


class _Verb(types.ModuleType):
    """This package once imported is `printgen.calibrate` (Python sets a subpackage as its
    parent's attribute), where the public verb `printgen.calibrate(...)` was: calling the
    package calls the verb, so a notebook's second call works as its first."""

    def __call__(self, *args: Any, **kwargs: Any) -> Calibration | WaveCalibration:
        return calibrate(*args, **kwargs)


sys.modules[__name__].__class__ = _Verb

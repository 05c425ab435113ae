"""The scene stage: the prototype and the printed model as solver nets, mounted and
instrumented as in the flume.

`build_scene(source, SceneOptions(...))` is the one way in: a frozen `SceneOptions` holds
every choice of a scene (mounting, panel-test orientation, pressure, net law, bed, sensor
routing, mounting span, load case, law factors, coarsening); a model-form
option is a transform that returns a new scene (`dataclasses.replace`), never mutates one.
Below it: the scene's arrays (`scenes`), its solver net (`solvernet`), the model-form
transforms (`forms`, `mount`, `pressure`; the scale series' rescaling: `scaled`), the
sensors' readings (`readings`), the flume drawing (`flume`) and the virtual panel test
(`panel`).
"""

from printgen.scene.options import SceneOptions, build_scene
from printgen.scene.scenes import BarrierScene

__all__ = ["BarrierScene", "SceneOptions", "build_scene"]

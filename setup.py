"""Build hook (the metadata is in pyproject.toml): the wheel ships the repository's top-level
`profiles/` (the bundled material, printer and print profiles), the example prototypes
`examples/*.toml`, the example notebook `examples/*.ipynb` and the example folders of data files
(`examples/paper_1_40/`: the paper's printed design and its measured test) inside the package,
as `printgen/profiles/` and `printgen/examples/`, where `printgen.inputs.profiles.bundled_dir`
reads them with importlib.resources. An editable install reads them where they are kept, at the
root of the checkout."""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

SHIPPED = {"profiles": ("*/*.toml",),  # folder -> the files copied from it
           "examples": ("*.toml", "*.ipynb", "paper_1_40/*.json", "paper_1_40/*.csv",
                        "calibration/*.toml")}


class BuildWithData(build_py):
    """`build_py`, plus the SHIPPED files copied into build/lib/printgen/<folder>/."""

    def run(self) -> None:
        super().run()
        if self.editable_mode:
            return
        for folder, patterns in SHIPPED.items():
            for src in sorted(f for pattern in patterns for f in Path(folder).glob(pattern)):
                dest = Path(self.build_lib, "printgen", src)
                self.mkpath(str(dest.parent))
                self.copy_file(str(src), str(dest))


setup(cmdclass={"build_py": BuildWithData})

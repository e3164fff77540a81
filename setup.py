"""The build step that ships the example model files (models/*.py) inside the package, as
lagrange_gen/example_models/, for `lagrange-gen examples`; everything else is in pyproject.toml."""

from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithExamples(build_py):
    """build_py, then models/*.py copied into the built package's example_models/."""

    def run(self):
        super().run()
        target = Path(self.build_lib) / "lagrange_gen" / "example_models"
        self.mkpath(str(target))
        for source in sorted(Path(__file__).resolve().parent.glob("models/*.py")):
            self.copy_file(str(source), str(target / source.name))


setup(cmdclass={"build_py": BuildWithExamples})

"""The package's files: its modules from ``src/``, and the bundled ``models/`` folder of the
repository as the package data ``turntable_pin/models`` (read with ``importlib.resources`` in an
installed wheel; a checkout or an editable install reads the repository's ``models/``). The
project's metadata is in ``pyproject.toml``."""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages("src"), "turntable_pin.models"],
    package_dir={"": "src", "turntable_pin.models": "models"},
    package_data={"turntable_pin.models": ["*.urdf", "*.yaml", "examples/**/*"]},
    include_package_data=False,
)

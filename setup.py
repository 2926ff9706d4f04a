"""Maps the top-level ``generated/`` and ``models/`` into the package (``symcat._generated``,
``symcat._models``) so that a non-editable install carries them; everything else is in
``pyproject.toml``."""
from setuptools import find_packages, setup

setup(
    packages=find_packages(include=["symcat", "symcat.*"]) + ["symcat._generated", "symcat._models"],
    package_dir={"symcat._generated": "generated", "symcat._models": "models"},
)

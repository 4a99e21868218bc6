"""What pyproject.toml cannot say: the bundled examples.

The repository keeps its models in one place, the top-level `models/` folder. The build maps that folder
into the package as `mbplanar.examples` (package data), so a wheel carries the models and an editable
install finds them in `models/` itself, without a second copy (docs/import_export.md, "Bundled examples").
"""

from setuptools import find_packages, setup

setup(packages=find_packages(include=["mbplanar", "mbplanar.*"]) + ["mbplanar.examples"],
      package_dir={"mbplanar.examples": "models"})

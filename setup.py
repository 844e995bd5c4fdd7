"""Maps plugins/, shaders/ and demos/ into the atmos package (see pyproject.toml)."""
from setuptools import find_namespace_packages, find_packages, setup

MAPPED = {"atmos.plugins": "plugins", "atmos.shaders": "shaders", "atmos.demos": "demos"}


def mapped_packages():
    packages = find_packages(include=["atmos", "atmos.*"])
    for name, folder in MAPPED.items():
        packages.append(name)
        packages += [f"{name}.{sub}" for sub in find_namespace_packages(folder, exclude=["*__pycache__*"])]
    return packages


setup(
    packages=mapped_packages(),
    package_dir={"atmos": "atmos", **MAPPED},
    package_data={"": ["*.glsl", "*.vert", "*.frag", "*.comp", "*.geom"], "atmos": ["py.typed"]},
)

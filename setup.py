"""Packaging: the shipped problem files are package data.

``problems/`` stays the user-visible folder at the top of the repository; it is installed
as the package ``optdesign.data.problems`` (a package-dir mapping, so no file is kept twice
in git) and :func:`optdesign.data.problems_dir` finds it there, so that ``optdesign bench``
and ``optdesign solve cs_min_backlash`` work after ``pip install .`` from any folder.
Everything else is in pyproject.toml.
"""

from setuptools import find_packages, setup

setup(
    packages=[*find_packages(include=["optdesign", "optdesign.*"]), "optdesign.data.problems"],
    package_dir={"optdesign.data.problems": "problems"},
)

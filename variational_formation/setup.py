# The Python package src/variational_formation (plots, CSV and scenario readers), installed by
# catkin_python_setup(). Do not run this file directly; catkin calls it.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["variational_formation"], package_dir={"": "src"}))

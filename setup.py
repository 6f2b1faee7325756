# The Python package mvog (python/mvog), with the extension mvog._mvog that CMakeLists.txt builds:
# catkin_python_setup() installs it beside the messages' mvog.msg and mvog.srv.
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["mvog"], package_dir={"": "python"}))

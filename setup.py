# catkin_python_setup() reads this; do not run it directly.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(
    **generate_distutils_setup(
        packages=["downstream_perception", "downstream_perception.replay", "downstream_perception.ros", "downstream_perception.sim"],
        package_dir={"": "src"},
    )
)

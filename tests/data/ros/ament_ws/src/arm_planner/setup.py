from setuptools import setup

package_name = 'arm_planner'

setup(
    name=package_name,
    version='2.0.1',
    packages=[package_name],
    data_files=[('share/' + package_name + '/launch', ['launch/arm.launch.py'])],
    entry_points={
        'console_scripts': [
            'planner = arm_planner.planner:main',
        ],
    },
)

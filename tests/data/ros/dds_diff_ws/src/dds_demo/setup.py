from setuptools import setup

package_name = 'dds_demo'

setup(
    name=package_name,
    version='1.0.0',
    packages=[package_name],
    data_files=[('share/' + package_name + '/launch', ['launch/demo.launch.py'])],
    entry_points={
        'console_scripts': [
            'sensor = dds_demo.sensor:main',
            'planner = dds_demo.planner:main',
        ],
    },
)

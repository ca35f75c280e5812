from setuptools import setup

setup(
    name='rover_tools',
    version='0.1.0',
    packages=['rover_tools'],
    data_files=[('share/ament_index/resource_index/packages', ['resource/rover_tools']),
                ('share/rover_tools', ['package.xml'])],
    install_requires=['setuptools'],
    entry_points={'console_scripts': ['beacon_node = rover_tools.beacon_node:main']},
)

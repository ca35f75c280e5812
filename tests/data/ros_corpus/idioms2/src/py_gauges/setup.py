from setuptools import setup

package_name = 'py_gauges'

setup(
    name=package_name,
    version='0.2.5',
    packages=[package_name],
    data_files=[('share/ament_index/resource_index/packages', ['resource/' + package_name]),
                ('share/' + package_name, ['package.xml'])],
    install_requires=['setuptools'],
    scripts=['scripts/gauge_panel'],
    entry_points={
        'console_scripts': [
            'gauge = py_gauges.gauge_node:main',
        ],
    },
)

from setuptools import setup

setup(
    name='py_tools',
    version='0.1.0',
    packages=['py_tools'],
    entry_points={'console_scripts': ['watchdog = py_tools.watchdog:main']},
)

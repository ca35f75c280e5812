from setuptools import setup

setup(
    name='twin_py',
    version='0.1.0',
    packages=['twin_py'],
    entry_points={'console_scripts': [
        'tanks = twin_py.tanks:main',
        'pump = twin_py.pump:main',
    ]},
)

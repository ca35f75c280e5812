from setuptools import setup

setup(
    name='pair_py',
    version='0.1.0',
    packages=['pair_py'],
    entry_points={'console_scripts': ['pair = pair_py.pair:main']},
)

from setuptools import setup

package_name = 'chat_py'

setup(
    name=package_name,
    version='0.1.0',
    packages=[package_name],
    data_files=[('share/ament_index/resource_index/packages', ['resource/' + package_name]),
                ('share/' + package_name, ['package.xml'])],
    install_requires=['setuptools'],
    entry_points={
        'console_scripts': [
            'talker = chat_py.talker:main',
            'relay = chat_py.relay:main',
        ],
    },
)

from glob import glob

from setuptools import find_packages, setup

package_name = 'pick_sim_world'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/launch', glob('launch/*_launch.py')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='pick_sim maintainers',
    maintainer_email='maintainers@pick-sim.dev',
    description='PyBullet world node of the picking-feasibility graph.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'world = pick_sim_world.start:main',
        ],
    },
)

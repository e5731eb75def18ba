from glob import glob
import os

from setuptools import find_packages, setup

package_name = 'experiment_manager'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
        ('share/' + package_name + '/config', ['config/default_experiment.yaml',
                                                'config/board_cell.yaml']),
        # the paper's test case, so that an installed workspace can run it by its share path
        ('share/' + package_name + '/config/test_case', sorted(glob('config/test_case/*.yaml'))),
        # parts from real CAD files, with their source and licence
        ('share/' + package_name + '/config/parts',
         sorted(p for p in glob('config/parts/*') if os.path.isfile(p))),
        ('share/' + package_name + '/config/parts/resting_rigid_bodies',
         sorted(glob('config/parts/resting_rigid_bodies/*'))),
        # a KiCad board and the 3D models it names, with their source and licence
        ('share/' + package_name + '/config/boards',
         sorted(p for p in glob('config/boards/*') if os.path.isfile(p))),
        *[('share/' + package_name + '/' + d, sorted(glob(d + '/*.step')))
          for d in sorted(glob('config/boards/3dmodels/*.3dshapes'))],
        ('share/' + package_name + '/launch', ['launch/experiment_launch.py']),
        # the Foxglove layout for recordings of a run in the root namespace (README)
        ('share/' + package_name + '/foxglove', ['foxglove/pick_sim_layout.json']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='pick_sim maintainers',
    maintainer_email='maintainers@pick-sim.dev',
    description='Runs the picking-feasibility experiments over the graph and records them.',
    license='Apache-2.0',
    entry_points={
        'console_scripts': [
            'experiment_manager = experiment_manager.graph.start:main',
            'run = experiment_manager.commands.run:main',
            'replay = experiment_manager.commands.replay:main',
            'decide = experiment_manager.commands.decide:main',
        ],
    },
)

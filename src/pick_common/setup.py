from setuptools import find_packages, setup

package_name = 'pick_common'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml', 'README.md']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='pick_sim maintainers',
    maintainer_email='maintainers@pick-sim.dev',
    description='The base package every package of the picking-feasibility graph shares.',
    license='Apache-2.0',
)

"""The whole graph on one machine: `workers` workers (`world`, `validity`, `feeder_controller`
under `<namespace>/worker_<k>`) and the `experiment_manager` under `<namespace>`. Send it
experiment files with the `run_experiment` action, e.g.

ros2 launch experiment_manager experiment_launch.py workers:=2
ros2 action send_goal --feedback /run_experiment pick_msgs/action/RunExperiment \
    "{experiment_file: $PWD/my_experiment.yaml}"

(the `run` executable does the same without ros2 launch: it starts these processes itself).
"""

from experiment_manager.launcher import MANAGER, READS_MESHES, WORKER_NODES
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def _nodes(context) -> list[Node]:
    namespace = LaunchConfiguration('namespace').perform(context).rstrip('/')
    workers = [f'worker_{k}' for k in range(int(LaunchConfiguration('workers')
                                                .perform(context)))]
    meshes = [d for d in LaunchConfiguration('mesh_dirs').perform(context).split(':') if d]
    nodes = [Node(package=package, executable=name, name=name,
                  namespace=f'{namespace}/{worker}', output='screen',
                  parameters=[{'mesh_dirs': meshes}] if meshes and name in READS_MESHES
                  else [])
             for worker in workers for package, name in WORKER_NODES]
    package, name = MANAGER
    nodes.append(Node(package=package, executable=name, name=name, namespace=namespace or '/',
                      output='screen', parameters=[{
                          'workers': workers,
                          'call_timeout': float(LaunchConfiguration('call_timeout')
                                                .perform(context))}]))
    return nodes


def generate_launch_description() -> LaunchDescription:
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='/',
                              description='namespace of the manager; worker k runs under '
                              '<namespace>/worker_<k>'),
        DeclareLaunchArgument('workers', default_value='1',
                              description='number of workers to start'),
        DeclareLaunchArgument('call_timeout', default_value='600.0',
                              description='longest wait for one call to a worker node, s'),
        DeclareLaunchArgument('mesh_dirs', default_value='',
                              description="':'-separated directories of the mesh files that "
                              'experiment files name (the workers read nothing else)'),
        OpaqueFunction(function=_nodes),
    ])

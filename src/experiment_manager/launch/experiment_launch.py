"""The whole graph on one machine: `workers` workers (`world`, `validity`, `feeder_controller`
under `<namespace>/worker_<k>`) and the `experiment_manager` under `<namespace>`. Send it
experiment files with the `run_experiment` action, e.g.

ros2 launch experiment_manager experiment_launch.py workers:=2 output_dirs:=$PWD/results
ros2 action send_goal --feedback /run_experiment pick_msgs/action/RunExperiment \
    "{experiment_file: $PWD/my_experiment.yaml}"

(the `run` executable does the same without ros2 launch: it starts these processes itself).
"""

from experiment_manager.commands.launcher import MANAGER, READS_MESHES, WORKER_NODES
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

# the manager's parameters that launch arguments of the same name set (besides `workers`)
NUMBERS = {'call_timeout': float, 'server_timeout': float, 'rejoin_timeout': float,
           'recording.chunk_size': int}
DIRECTORIES = ('experiment_dirs', 'output_dirs')


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
    parameters = {'workers': workers,
                  **{key: kind(LaunchConfiguration(key).perform(context))
                     for key, kind in NUMBERS.items()}}
    for key in DIRECTORIES:   # empty: the node's default
        dirs = [d for d in LaunchConfiguration(key).perform(context).split(':') if d]
        if dirs:
            parameters[key] = dirs
    nodes.append(Node(package=package, executable=name, name=name, namespace=namespace or '/',
                      output='screen', parameters=[parameters]))
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
        DeclareLaunchArgument('server_timeout', default_value='10.0',
                              description="longest wait for the workers' services and actions "
                              'at the start of a run, s'),
        DeclareLaunchArgument('rejoin_timeout', default_value='60.0',
                              description='longest wait for a lost worker to come back, s; 0: '
                              'do not wait'),
        DeclareLaunchArgument('recording.chunk_size', default_value='1048576',
                              description='bytes of messages per MCAP chunk; a killed run '
                              'loses at most one'),
        DeclareLaunchArgument('experiment_dirs', default_value='',
                              description="':'-separated directories whose experiment files "
                              "goals may name; empty: the node's default (its working "
                              'directory and the built-in files)'),
        DeclareLaunchArgument('output_dirs', default_value='',
                              description="':'-separated directories under which goals may "
                              "write run directories; empty: the node's working directory"),
        DeclareLaunchArgument('mesh_dirs', default_value='',
                              description="':'-separated directories of the mesh files that "
                              'experiment files name (the workers read nothing else)'),
        OpaqueFunction(function=_nodes),
    ])

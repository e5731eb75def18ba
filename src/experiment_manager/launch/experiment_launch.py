"""The whole graph on one machine: a worker (`world`, `validity`, `feeder_controller` under
`<namespace>/worker_0`) and the `experiment_manager` under `<namespace>`. Send it experiment files
with the `run_experiment` action, e.g.

ros2 launch experiment_manager experiment_launch.py
ros2 action send_goal --feedback /run_experiment pick_msgs/action/RunExperiment \
    "{experiment_file: $PWD/my_experiment.yaml}"

(the `run` executable does the same without ros2 launch: it starts these processes itself).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration, PythonExpression
from launch_ros.actions import Node

WORKER = 'worker_0'


def generate_launch_description() -> LaunchDescription:
    namespace = LaunchConfiguration('namespace')
    worker_ns = PythonExpression(["'", namespace, "'.rstrip('/') + '/", WORKER, "'"])
    worker = [Node(package=package, executable=name, name=name, namespace=worker_ns,
                   output='screen')
              for package, name in (('pick_sim_world', 'world'), ('pick_validity', 'validity'),
                                    ('feeder_controller', 'feeder_controller'))]
    manager = Node(package='experiment_manager', executable='experiment_manager',
                   name='experiment_manager', namespace=namespace, output='screen',
                   parameters=[{'worker': WORKER,
                                'call_timeout': LaunchConfiguration('call_timeout')}])
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='/',
                              description='namespace of the manager; the worker runs under '
                              f'<namespace>/{WORKER}'),
        DeclareLaunchArgument('call_timeout', default_value='600.0',
                              description='longest wait for one call to a worker node, s'),
        *worker, manager,
    ])

"""Start one `feeder_controller` node, optionally under a namespace (a worker) with a parameter
file. It commands the `world` of its own namespace, so start that world there too.

ros2 launch feeder_controller feeder_controller_launch.py namespace:=worker_1
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    default_params = os.path.join(get_package_share_directory('feeder_controller'), 'config',
                                  'feeder.yaml')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the node, e.g. worker_1'),
        DeclareLaunchArgument('params_file', default_value=default_params,
                              description='parameter file of the feeder_controller node'),
        Node(package='feeder_controller', executable='feeder_controller',
             name='feeder_controller', namespace=LaunchConfiguration('namespace'),
             parameters=[LaunchConfiguration('params_file')], output='screen'),
    ])

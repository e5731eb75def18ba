"""Start one `validity` node, optionally under a namespace (a worker) with a parameter file.

ros2 launch pick_validity validity_launch.py namespace:=worker_1
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node


def generate_launch_description() -> LaunchDescription:
    default_params = os.path.join(get_package_share_directory('pick_validity'), 'config',
                                  'paper_gripper.yaml')
    return LaunchDescription([
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the node, e.g. worker_1'),
        DeclareLaunchArgument('params_file', default_value=default_params,
                              description='parameter file of the validity node'),
        Node(package='pick_validity', executable='validity', name='validity',
             namespace=LaunchConfiguration('namespace'),
             parameters=[LaunchConfiguration('params_file')], output='screen'),
    ])

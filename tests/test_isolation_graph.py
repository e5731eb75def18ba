"""Who can reach the nodes. The Fast DDS of the PyPI wheels has no DDS Security: a node told to
enforce it refuses to start, so enclaves cannot keep anyone out here (docs/reliability.md). What
does isolate: another ROS_DOMAIN_ID, and ROS_AUTOMATIC_DISCOVERY_RANGE (OFF: nothing finds the
node; LOCALHOST, which the tests use: nothing off this host, which one machine cannot test)."""


from graph import NodeProcess, unique_namespace
from pick_msgs.srv import CheckParts
import pytest
import rclpy
from rclpy.context import Context

pytestmark = pytest.mark.graph
NS = unique_namespace('iso')
ENCLAVE_FILES = ('identity_ca.cert.pem', 'cert.pem', 'key.pem', 'permissions_ca.cert.pem',
                 'governance.p7s', 'permissions.p7s')


def reachable(namespace: str, domain: int, wait: float) -> bool:
    """Whether a client in `domain` (discovery range of this process) finds check_parts."""
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    try:
        node = rclpy.create_node('probe', context=context)
        found = node.create_client(CheckParts, f'{namespace}/check_parts').wait_for_service(
            timeout_sec=wait)
        node.destroy_node()
        return found
    finally:
        rclpy.try_shutdown(context=context)


def test_a_node_told_to_enforce_dds_security_refuses_to_start(tmp_path, monkeypatch):
    enclave = tmp_path / 'keystore' / 'enclaves' / 'cell'
    enclave.mkdir(parents=True)
    for name in ENCLAVE_FILES:     # the files rcl looks for; their content is never reached
        (enclave / name).write_text('placeholder\n')
    monkeypatch.setenv('ROS_SECURITY_ENABLE', 'true')
    monkeypatch.setenv('ROS_SECURITY_STRATEGY', 'Enforce')
    monkeypatch.setenv('ROS_SECURITY_KEYSTORE', str(tmp_path / 'keystore'))
    monkeypatch.setenv('ROS_SECURITY_ENCLAVE_OVERRIDE', '/cell')
    proc = NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}/sec'])
    assert proc.process.wait(60) == 2, proc.output()
    assert "This Fast DDS version doesn't have the security libraries" in proc.output()
    assert 'validity: could not start:' in proc.output() and 'Traceback' not in proc.output()


def test_another_domain_or_discovery_off_keeps_a_client_out(private_ros_domain, monkeypatch):
    open_node = NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}/open'])
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'OFF')
    hidden = NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}/hidden'])
    monkeypatch.setenv('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    try:
        assert reachable(f'{NS}/open', private_ros_domain, 60.0)
        assert not reachable(f'{NS}/open', (private_ros_domain + 1) % 100, 5.0)
        assert not reachable(f'{NS}/hidden', private_ros_domain, 5.0)
        assert hidden.running(), hidden.output()
    finally:
        assert open_node.stop() == 0 and hidden.stop() == 0

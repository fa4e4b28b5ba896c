"""lugrip on ROS 2: a managed (lifecycle) node around :class:`lugrip.SlipControl`
(:mod:`lugrip.ros.node`) and a MuJoCo gripper node to run it against (:mod:`lugrip.ros.sim`).

Needs the ``[ros]`` extra (ROS 2 Kilted's rclpy and message packages as pip wheels):
``pip install "lugrip[ros]"``; the parameter tables (:mod:`lugrip.ros._parameters`) do not.
docs/ros.md describes the topics, parameters, services, timing and fault handling.
"""

from __future__ import annotations

__all__ = ["available", "missing_message"]


def available() -> bool:
    """rclpy and the message packages the nodes use can be imported."""
    try:
        import diagnostic_msgs.msg  # noqa: F401
        import geometry_msgs.msg  # noqa: F401
        import rclpy  # noqa: F401
        import rclpy.lifecycle  # noqa: F401
        import sensor_msgs.msg  # noqa: F401
        import std_msgs.msg  # noqa: F401
        import std_srvs.srv  # noqa: F401
    except ImportError:
        return False
    return True


def missing_message() -> str:
    return ("ROS 2 (rclpy and its message packages) is not installed: "
            "pip install \"lugrip[ros]\" (ROS 2 Kilted wheels)")

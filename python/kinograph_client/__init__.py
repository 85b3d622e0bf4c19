"""kinograph's Python client: send goals to a kinographd over LCM and receive its plans.

Uses the generated message types (package ``kinograph``) and a small ctypes binding of
liblcm (lcm_ctypes), since Debian has no LCM Python module."""

from .client import (STATUS_NAMES, PlannerClient, detach_payload, joint_goal, mesh_obstacle,
                     now_utime, payload, pose_goal)
from .lcm_ctypes import Lcm, LcmError, Subscription

__all__ = ["Lcm", "LcmError", "PlannerClient", "STATUS_NAMES", "Subscription", "detach_payload",
           "joint_goal", "mesh_obstacle", "now_utime", "payload", "pose_goal"]

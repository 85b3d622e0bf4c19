"""Asking a kinographd for plans from Python: publish a goal_t on <PREFIX>_GOAL and wait for
the plan_t on <PREFIX>_PLAN that answers its goal_id."""

import struct
import time

from kinograph import goal_t, goal_v2_t, plan_t

from .lcm_ctypes import Lcm

# plan_t.status by value, for messages.
STATUS_NAMES = {plan_t.SUCCESS: "SUCCESS", plan_t.FAILED: "FAILED",
                plan_t.INVALID_GOAL: "INVALID_GOAL", plan_t.INVALID_STATE: "INVALID_STATE",
                plan_t.CANCELLED: "CANCELLED", plan_t.NOT_CONVERGED: "NOT_CONVERGED",
                plan_t.SUPERSEDED: "SUPERSEDED"}


def now_utime():
    """The time now in microseconds since the epoch, as messages carry it."""
    return time.time_ns() // 1000


def _goal_header(goal, goal_id, duration_s, robot):
    goal.utime = now_utime()
    goal.goal_id = goal.utime if goal_id is None else goal_id
    goal.robot = robot
    goal.duration_s = float(duration_s)
    return goal


def joint_goal(q, goal_id=None, duration_s=0.0, robot=""):
    """A joint goal: `q` a mapping {joint name: rad}, any order, a subset (the joints not
    named are held at their start), as a goal_v2_t; or a sequence of every joint in the
    robot's URDF order, as a goal_t. goal_id defaults to the time in µs; duration_s 0 is the
    daemon's horizon; robot "" is any robot."""
    if hasattr(q, "items"):
        goal = _goal_header(goal_v2_t(), goal_id, duration_s, robot)
        goal.kind = goal_v2_t.KIND_JOINT_CONFIGURATION
        goal.joint_name = [str(name) for name in q]
        goal.joint_position = [float(x) for x in q.values()]
        goal.num_joints = len(goal.joint_name)
        goal.task_constraint = []
        goal.num_task_constraints = 0
    else:
        goal = _goal_header(goal_t(), goal_id, duration_s, robot)
        goal.kind = goal_t.KIND_JOINT_CONFIGURATION
        goal.joint_position = [float(x) for x in q]
        goal.num_joints = len(goal.joint_position)
    goal.ee_position = [0.0, 0.0, 0.0]
    goal.ee_quaternion = [1.0, 0.0, 0.0, 0.0]
    return goal


def pose_goal(frame, position, quaternion=None, position_only=False, goal_id=None,
              duration_s=0.0, robot=""):
    """A goal_v2_t for the world pose of `frame` (a URDF link or frame): `position` (x, y, z)
    in m and `quaternion` (w, x, y, z); with position_only the orientation is free and
    `quaternion` must be left out. Raises ValueError for a missing or extra orientation or a
    wrong length."""
    position = [float(x) for x in position]
    if len(position) != 3:
        raise ValueError(f"pose_goal: position has {len(position)} values, needs x, y, z")
    if position_only and quaternion is not None:
        raise ValueError("pose_goal: position_only ignores the orientation: leave out quaternion")
    if not position_only and quaternion is None:
        raise ValueError("pose_goal: give quaternion (w, x, y, z; 1, 0, 0, 0 = the world's "
                         "axes) or position_only=True")
    quaternion = [1.0, 0.0, 0.0, 0.0] if quaternion is None else [float(x) for x in quaternion]
    if len(quaternion) != 4:
        raise ValueError(f"pose_goal: quaternion has {len(quaternion)} values, needs w, x, y, z")
    goal = _goal_header(goal_v2_t(), goal_id, duration_s, robot)
    goal.kind = goal_v2_t.KIND_END_EFFECTOR_POSE
    goal.joint_name, goal.joint_position, goal.num_joints = [], [], 0
    goal.ee_frame = str(frame)
    goal.ee_position = position
    goal.ee_quaternion = quaternion
    goal.position_only = bool(position_only)
    goal.task_constraint = []
    goal.num_task_constraints = 0
    return goal


class PlannerClient:
    """A connection to the kinographd serving channels <prefix>_* on the LCM `url`
    (None: LCM's default)."""

    def __init__(self, prefix, url=None):
        self.prefix = prefix
        #: The LCM connection, for other messages to the daemon (obstacle_list_t, ...).
        self.lcm = Lcm(url)
        self._plans = []
        # Subscribed before any goal is sent, so that a fast answer is not missed.
        self.lcm.subscribe(f"{prefix}_PLAN", lambda _channel, data: self._plans.append(data))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def send(self, goal):
        """Publishes `goal` (a goal_v2_t or goal_t) on <prefix>_GOAL."""
        self.lcm.publish(f"{self.prefix}_GOAL", goal.encode())

    def wait_for_plan(self, goal_id, timeout_s):
        """The first plan_t answering `goal_id` received since this client was made (plans
        for other goals are skipped). Raises TimeoutError after `timeout_s` seconds, and
        ValueError for a message on <prefix>_PLAN that is not a plan_t."""
        deadline = time.monotonic() + timeout_s
        while True:
            while self._plans:
                data = self._plans.pop(0)
                try:
                    plan = plan_t.decode(data)
                except (ValueError, struct.error) as e:
                    raise ValueError(f"{self.prefix}_PLAN: a message that is not a kinograph "
                                     f"plan_t ({len(data)} bytes: {e})") from None
                if plan.goal_id == goal_id:
                    return plan
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"no plan for goal {goal_id} on {self.prefix}_PLAN "
                                   f"within {timeout_s:g} s")
            self.lcm.handle(remaining)

    def plan(self, goal, timeout_s=60.0):
        """Sends `goal` and returns the plan_t answering it, whatever its status (see
        STATUS_NAMES); raises TimeoutError when none comes within `timeout_s` seconds."""
        self.send(goal)
        return self.wait_for_plan(goal.goal_id, timeout_s)

    def close(self):
        """Closes the LCM connection."""
        self.lcm.close()

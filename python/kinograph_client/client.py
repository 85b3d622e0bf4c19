"""Asking a kinographd for plans from Python: publish a goal_t on <PREFIX>_GOAL and wait for
the plan_t on <PREFIX>_PLAN that answers its goal_id."""

import struct
import time

from kinograph import goal_t, plan_t

from .lcm_ctypes import Lcm

# plan_t.status by value, for messages.
STATUS_NAMES = {plan_t.SUCCESS: "SUCCESS", plan_t.FAILED: "FAILED",
                plan_t.INVALID_GOAL: "INVALID_GOAL", plan_t.INVALID_STATE: "INVALID_STATE",
                plan_t.CANCELLED: "CANCELLED", plan_t.NOT_CONVERGED: "NOT_CONVERGED",
                plan_t.SUPERSEDED: "SUPERSEDED"}


def now_utime():
    """The time now in microseconds since the epoch, as messages carry it."""
    return time.time_ns() // 1000


def joint_goal(q, goal_id=None, duration_s=0.0, robot=""):
    """A goal_t for the joint configuration `q` (rad, the robot's URDF joint order).
    goal_id defaults to the time in µs; duration_s 0 is the daemon's horizon; robot ""
    is any robot."""
    goal = goal_t()
    goal.utime = now_utime()
    goal.goal_id = goal.utime if goal_id is None else goal_id
    goal.robot = robot
    goal.kind = goal_t.KIND_JOINT_CONFIGURATION
    goal.joint_position = [float(x) for x in q]
    goal.num_joints = len(goal.joint_position)
    goal.ee_position = [0.0, 0.0, 0.0]
    goal.ee_quaternion = [1.0, 0.0, 0.0, 0.0]
    goal.duration_s = float(duration_s)
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
        """Publishes `goal` (a goal_t) on <prefix>_GOAL."""
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

"""Asking a kinographd for plans from Python: publish a goal (goal_t, goal_v2_t or, with
tolerances, goal_v3_t) on <PREFIX>_GOAL and wait for the plan_t on <PREFIX>_PLAN that answers
its goal_id; attach or detach a payload (payload_t on <PREFIX>_PAYLOAD) and add mesh obstacles
by file (mesh_obstacle_list_t on <PREFIX>_OBSTACLES)."""

import struct
import time

from kinograph import (goal_t, goal_v2_t, goal_v3_t, mesh_obstacle_list_t, mesh_obstacle_t,
                       payload_t, plan_t)

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


def _floats(values, what, n):
    values = [float(x) for x in values]
    if len(values) != n:
        raise ValueError(f"{what} has {len(values)} values, needs {n}")
    return values


def _named_goal(tolerant):
    """An empty goal of version 3 when it carries tolerances, else of version 2."""
    goal = goal_v3_t() if tolerant else goal_v2_t()
    goal.task_constraint = []
    goal.num_task_constraints = 0
    return goal


def joint_goal(q, goal_id=None, duration_s=0.0, robot="", tolerance=None):
    """A joint goal: `q` a mapping {joint name: rad}, any order, a subset (the joints not
    named are held at their start), as a goal_v2_t; or a sequence of every joint in the
    robot's URDF order, as a goal_t. goal_id defaults to the time in µs; duration_s 0 is the
    daemon's horizon; robot "" is any robot. `tolerance` {joint name: rad} (joints of `q`)
    says how far each may end from its goal (default 0.01), as a goal_v3_t. Raises ValueError
    for a tolerance of a joint `q` does not name, or with a sequence `q`."""
    if hasattr(q, "items"):
        goal = _goal_header(_named_goal(tolerance is not None), goal_id, duration_s, robot)
        goal.kind = goal_v2_t.KIND_JOINT_CONFIGURATION
        goal.joint_name = [str(name) for name in q]
        goal.joint_position = [float(x) for x in q.values()]
        goal.num_joints = len(goal.joint_name)
        if tolerance is not None:
            unknown = [name for name in tolerance if name not in q]
            if unknown:
                raise ValueError(f"joint_goal: tolerance of {unknown[0]!r}, a joint the goal "
                                 "does not name")
            goal.joint_tolerance = [float(tolerance.get(name, 0.0)) for name in goal.joint_name]
    else:
        if tolerance is not None:
            raise ValueError("joint_goal: tolerances need the joints by name ({name: rad})")
        goal = _goal_header(goal_t(), goal_id, duration_s, robot)
        goal.kind = goal_t.KIND_JOINT_CONFIGURATION
        goal.joint_position = [float(x) for x in q]
        goal.num_joints = len(goal.joint_position)
    goal.ee_position = [0.0, 0.0, 0.0]
    goal.ee_quaternion = [1.0, 0.0, 0.0, 0.0]
    return goal


def pose_goal(frame, position, quaternion=None, position_only=False, goal_id=None,
              duration_s=0.0, robot="", position_tolerance=None, orientation_tolerance=None):
    """A goal_v2_t for the world pose of `frame` (a URDF link or frame): `position` (x, y, z)
    in m and `quaternion` (w, x, y, z); with position_only the orientation is free and
    `quaternion` must be left out. With position_tolerance (m) or orientation_tolerance (rad),
    how far the frame may end from them (default 0.01), a goal_v3_t. Raises ValueError for a
    missing or extra orientation or a wrong length."""
    position = _floats(position, "pose_goal: position", 3)
    if position_only and quaternion is not None:
        raise ValueError("pose_goal: position_only ignores the orientation: leave out quaternion")
    if not position_only and quaternion is None:
        raise ValueError("pose_goal: give quaternion (w, x, y, z; 1, 0, 0, 0 = the world's "
                         "axes) or position_only=True")
    quaternion = ([1.0, 0.0, 0.0, 0.0] if quaternion is None
                  else _floats(quaternion, "pose_goal: quaternion", 4))
    tolerant = position_tolerance is not None or orientation_tolerance is not None
    goal = _goal_header(_named_goal(tolerant), goal_id, duration_s, robot)
    goal.kind = goal_v2_t.KIND_END_EFFECTOR_POSE
    goal.joint_name, goal.joint_position, goal.num_joints = [], [], 0
    goal.ee_frame = str(frame)
    goal.ee_position = position
    goal.ee_quaternion = quaternion
    goal.position_only = bool(position_only)
    if tolerant:
        goal.joint_tolerance = []
        goal.position_tolerance_m = float(position_tolerance or 0.0)
        goal.orientation_tolerance_rad = float(orientation_tolerance or 0.0)
    return goal


def payload(frame, mass_kg, size, offset=(0.0, 0.0, 0.0), robot=""):
    """A payload_t attaching a solid box to `frame` (a URDF link or frame), as a scene's
    robot.payload: mass in kg, full extents `size` (x, y, z) in m, its centre at `offset` in
    `frame`. The daemon's next plans carry it. Raises ValueError for a wrong length."""
    msg = payload_t()
    msg.utime = now_utime()
    msg.robot = robot
    msg.action = payload_t.ATTACH
    msg.frame = str(frame)
    msg.mass_kg = float(mass_kg)
    msg.size = _floats(size, "payload: size", 3)
    msg.offset = _floats(offset, "payload: offset", 3)
    return msg


def detach_payload(robot=""):
    """A payload_t detaching the payload: the daemon's next plans are for the bare robot."""
    msg = payload_t()
    msg.utime = now_utime()
    msg.robot = robot
    msg.action = payload_t.DETACH
    msg.frame, msg.mass_kg, msg.size, msg.offset = "", 0.0, [0.0] * 3, [0.0] * 3
    return msg


def mesh_obstacle(obstacle_id, mesh, position, quaternion=(1.0, 0.0, 0.0, 0.0),
                  scale=(1.0, 1.0, 1.0), source="", remove=False):
    """A mesh_obstacle_list_t adding (or moving, or with remove removing) the convex hull of
    mesh file `mesh` as the daemon's machine sees it (absolute, or relative to the daemon's
    scene, then its data directories), its origin at `position` (m), turned by `quaternion`
    (w, x, y, z), scaled per axis. Raises ValueError for a wrong length."""
    o = mesh_obstacle_t()
    o.id = str(obstacle_id)
    o.action = mesh_obstacle_t.REMOVE if remove else mesh_obstacle_t.ADD_OR_MOVE
    o.mesh = str(mesh)
    o.scale = _floats(scale, "mesh_obstacle: scale", 3)
    o.position = _floats(position, "mesh_obstacle: position", 3)
    o.quaternion = _floats(quaternion, "mesh_obstacle: quaternion", 4)
    msg = mesh_obstacle_list_t()
    msg.utime = now_utime()
    msg.source = source
    msg.obstacles = [o]
    msg.num_obstacles = 1
    return msg


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
        """Publishes `goal` (a goal_t, goal_v2_t or goal_v3_t) on <prefix>_GOAL."""
        self.lcm.publish(f"{self.prefix}_GOAL", goal.encode())

    def send_payload(self, msg):
        """Publishes a payload_t (payload(), detach_payload()) on <prefix>_PAYLOAD; a refusal
        is reported on <prefix>_PLANNER_STATUS."""
        self.lcm.publish(f"{self.prefix}_PAYLOAD", msg.encode())

    def send_obstacles(self, msg):
        """Publishes an obstacle_list_t or mesh_obstacle_list_t on <prefix>_OBSTACLES."""
        self.lcm.publish(f"{self.prefix}_OBSTACLES", msg.encode())

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

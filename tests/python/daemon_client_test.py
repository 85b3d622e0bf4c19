"""The Python client against a running kinographd (started by daemon_client_test.sh on
robots/scenes/rr_reach.yaml): a joint goal sent from Python is answered by a valid plan that
ends at the goal, decoded with the generated types; goals by joint name (goal_v2_t) and a
position-only pose goal are planned; an unknown joint name and a goal with the wrong number of
joints are answered INVALID_GOAL with their reason; a payload attached from Python changes the
torque the arm holds at the goal, detached it does not; a tight goal tolerance is met. The daemon takes goal ids 1, 2, 3, ... as a
sequence (gaps are losses), so the ids follow the tests' (alphabetical) order.
Usage: daemon_client_test.py URL PREFIX URDF, with share/kinograph/python on PYTHONPATH."""

import math
import sys
import unittest
import xml.etree.ElementTree as ET

from kinograph import plan_t
from kinograph_client import (STATUS_NAMES, PlannerClient, detach_payload, joint_goal, payload,
                              pose_goal)

URL, PREFIX, URDF = sys.argv[1:4]
del sys.argv[1:4]
# rr_reach.yaml's start and horizon; the goal differs from the scene's own (1.2, 0).
START = [-1.2, 0.0]
HORIZON_S = 3.0
GOAL = [1.0, 0.3]
TIMEOUT_S = 120.0  # a busy machine; the plan takes well under a second when idle


def urdf_joint_names(path):
    """The moving joints of a URDF, in document order (the daemon's order for this arm)."""
    return [j.get("name") for j in ET.parse(path).getroot().iter("joint")
            if j.get("type") != "fixed"]


class DaemonTestCase(unittest.TestCase):
    """One client for the tests of a class."""

    @classmethod
    def setUpClass(cls):
        cls.client = PlannerClient(PREFIX, URL)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()


class PythonClientAgainstDaemon(DaemonTestCase):

    def test_joint_goal_is_planned(self):
        plan = self.client.plan(joint_goal(GOAL, goal_id=2), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.SUCCESS,
                         f"{STATUS_NAMES.get(plan.status)}: {plan.status_message}")
        self.assertTrue(plan.valid)
        self.assertEqual(plan.goal_id, 2)
        names = urdf_joint_names(URDF)
        self.assertEqual(plan.num_joints, len(names))
        self.assertEqual(list(plan.joint_name), names)
        self.assertGreater(plan.num_steps, 2)
        for name in ("t", "q", "qd", "qdd", "tau"):
            self.assertEqual(len(getattr(plan, name)), plan.num_steps, name)
        self.assertEqual(plan.t[0], 0.0)
        self.assertAlmostEqual(plan.t[-1], HORIZON_S, places=9)
        self.assertTrue(all(b > a for a, b in zip(plan.t, plan.t[1:])), "t not increasing")
        for j in range(plan.num_joints):
            self.assertAlmostEqual(plan.q[0][j], START[j], delta=1e-6, msg=f"start, joint {j}")
            self.assertAlmostEqual(plan.q[-1][j], GOAL[j], delta=1e-3, msg=f"goal, joint {j}")
            self.assertAlmostEqual(plan.qd[-1][j], 0.0, delta=1e-2, msg=f"rest, joint {j}")
        self.assertTrue(all(math.isfinite(x) for row in plan.tau for x in row))
        self.assertLess(plan.goal_error, 1e-3)

    def test_goal_by_joint_name_holds_the_joints_not_named(self):
        plan = self.client.plan(joint_goal({"joint2": GOAL[1]}, goal_id=1), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.SUCCESS,
                         f"{STATUS_NAMES.get(plan.status)}: {plan.status_message}")
        self.assertAlmostEqual(plan.q[-1][0], START[0], delta=1e-3, msg="joint1 held")
        self.assertAlmostEqual(plan.q[-1][1], GOAL[1], delta=1e-3, msg="joint2 moved")

    def test_unknown_joint_name_is_refused_naming_it(self):
        plan = self.client.plan(joint_goal({"joint1": 0.1, "shoulder": 0.2}, goal_id=4),
                                timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.INVALID_GOAL, STATUS_NAMES.get(plan.status))
        self.assertIn('"shoulder" is not a joint of rr', plan.status_message)

    def test_position_only_pose_goal_is_planned(self):
        # The tip of rr's 1 m and 0.8 m links (joint axes y, links along z) at GOAL.
        x = math.sin(GOAL[0]) + 0.8 * math.sin(GOAL[0] + GOAL[1])
        z = math.cos(GOAL[0]) + 0.8 * math.cos(GOAL[0] + GOAL[1])
        plan = self.client.plan(pose_goal("ee", (x, 0.0, z), position_only=True,
                                          goal_id=3), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.SUCCESS,
                         f"{STATUS_NAMES.get(plan.status)}: {plan.status_message}")
        self.assertLess(plan.goal_error, 1e-2)

    def test_wrong_joint_count_is_refused(self):
        plan = self.client.plan(joint_goal([0.1, 0.2, 0.3], goal_id=5), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.INVALID_GOAL, STATUS_NAMES.get(plan.status))
        self.assertEqual(plan.num_steps, 0)
        self.assertIn("3", plan.status_message)


class PythonClientSceneMessages(DaemonTestCase):
    """Runs after PythonClientAgainstDaemon (class names in order): goal ids 6, 7, ..."""

    def plan(self, goal):
        plan = self.client.plan(goal, timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.SUCCESS,
                         f"{STATUS_NAMES.get(plan.status)}: {plan.status_message}")
        return plan

    def test_a_payload_is_carried_until_detached(self):
        bare = self.plan(joint_goal(GOAL, goal_id=6))
        # 1 kg at the tip of the 0.8 m link: at the goal, joint 2 holds its weight too.
        self.client.send_payload(payload("ee", 1.0, (0.05, 0.05, 0.05)))
        carried = self.plan(joint_goal(GOAL, goal_id=7))
        lever = 0.8 * math.sin(GOAL[0] + GOAL[1])
        self.assertAlmostEqual(abs(carried.tau[-1][1] - bare.tau[-1][1]), 1.0 * 9.81 * abs(lever),
                               delta=0.05)
        self.client.send_payload(detach_payload())
        detached = self.plan(joint_goal(GOAL, goal_id=8))
        self.assertAlmostEqual(detached.tau[-1][1], bare.tau[-1][1], delta=1e-3)

    def test_b_a_tight_goal_tolerance_is_met(self):
        plan = self.plan(joint_goal({"joint1": 0.9, "joint2": 0.2}, goal_id=9,
                                    tolerance={"joint1": 1e-4, "joint2": 1e-4}))
        self.assertLessEqual(plan.goal_error, 1e-4)


if __name__ == "__main__":
    unittest.main()

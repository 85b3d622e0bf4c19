"""The Python client against a running kinographd (started by daemon_client_test.sh on
robots/scenes/rr_reach.yaml): a joint goal sent from Python is answered by a valid plan that
ends at the goal, decoded with the generated types; a goal with the wrong number of joints is
answered INVALID_GOAL with its reason.
Usage: daemon_client_test.py URL PREFIX URDF, with share/kinograph/python on PYTHONPATH."""

import math
import sys
import unittest
import xml.etree.ElementTree as ET

from kinograph import plan_t
from kinograph_client import STATUS_NAMES, PlannerClient, joint_goal

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


class PythonClientAgainstDaemon(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.client = PlannerClient(PREFIX, URL)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()

    def test_joint_goal_is_planned(self):
        plan = self.client.plan(joint_goal(GOAL, goal_id=1), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.SUCCESS,
                         f"{STATUS_NAMES.get(plan.status)}: {plan.status_message}")
        self.assertTrue(plan.valid)
        self.assertEqual(plan.goal_id, 1)
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

    def test_wrong_joint_count_is_refused(self):
        plan = self.client.plan(joint_goal([0.1, 0.2, 0.3], goal_id=2), timeout_s=TIMEOUT_S)
        self.assertEqual(plan.status, plan_t.INVALID_GOAL, STATUS_NAMES.get(plan.status))
        self.assertEqual(plan.num_steps, 0)
        self.assertIn("3", plan.status_message)


if __name__ == "__main__":
    unittest.main()

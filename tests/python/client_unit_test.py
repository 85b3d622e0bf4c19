"""The Python side on its own, over memq:// (in-process LCM): the generated types, the ctypes
binding of liblcm and the client's wait for the plan that answers its goal.
Usage: client_unit_test.py LCMTYPES_DIR, with the build tree's share/kinograph/python on
PYTHONPATH."""

import glob
import os
import re
import sys
import time
import unittest

import kinograph
from kinograph import (goal_t, goal_v2_t, goal_v3_t, mesh_obstacle_list_t, mesh_obstacle_t,
                       payload_t, plan_t)
from kinograph_client import (Lcm, LcmError, PlannerClient, detach_payload, joint_goal,
                              mesh_obstacle, payload, pose_goal)

LCMTYPES_DIR = sys.argv.pop(1)


def empty_plan(goal_id):
    plan = plan_t()
    plan.goal_id = goal_id
    plan.joint_name, plan.t, plan.q, plan.qd, plan.qdd, plan.tau = [], [], [], [], [], []
    return plan


class GeneratedTypes(unittest.TestCase):
    def test_every_struct_is_generated(self):
        files = sorted(glob.glob(os.path.join(LCMTYPES_DIR, "*.lcm")))
        self.assertTrue(files, f"no .lcm file in {LCMTYPES_DIR}")
        structs = []
        for name in files:
            with open(name) as f:
                structs += re.findall(r"^struct (\w+)", f.read(), re.MULTILINE)
        self.assertGreaterEqual(len(structs), len(files))
        for struct in structs:
            cls = getattr(kinograph, struct, None)
            self.assertIsNotNone(cls, f"kinograph.{struct} was not generated")
            self.assertEqual(len(cls._get_packed_fingerprint()), 8, struct)

    def test_goal_round_trip(self):
        goal = joint_goal([0.5, -1.25], goal_id=42, duration_s=2.5, robot="rr")
        back = goal_t.decode(goal.encode())
        self.assertEqual(back.goal_id, 42)
        self.assertEqual(back.kind, goal_t.KIND_JOINT_CONFIGURATION)
        self.assertEqual(back.num_joints, 2)
        self.assertEqual(list(back.joint_position), [0.5, -1.25])
        self.assertEqual(back.duration_s, 2.5)
        self.assertEqual(back.robot, "rr")
        self.assertEqual(list(back.ee_quaternion), [1.0, 0.0, 0.0, 0.0])

    def test_named_joint_goal_is_a_goal_v2(self):
        goal = joint_goal({"joint2": 0.5, "joint1": -1.25}, goal_id=43)
        back = goal_v2_t.decode(goal.encode())
        self.assertEqual(back.goal_id, 43)
        self.assertEqual(back.kind, goal_v2_t.KIND_JOINT_CONFIGURATION)
        self.assertEqual(list(back.joint_name), ["joint2", "joint1"])
        self.assertEqual(list(back.joint_position), [0.5, -1.25])
        self.assertEqual(back.num_task_constraints, 0)
        with self.assertRaises(ValueError):  # the fingerprints differ
            goal_t.decode(goal.encode())

    def test_pose_goal(self):
        goal = pose_goal("ee", (0.1, 0.2, 1.5), (0, 1, 0, 0), goal_id=44, duration_s=2)
        back = goal_v2_t.decode(goal.encode())
        self.assertEqual(back.kind, goal_v2_t.KIND_END_EFFECTOR_POSE)
        self.assertEqual(back.ee_frame, "ee")
        self.assertEqual(list(back.ee_position), [0.1, 0.2, 1.5])
        self.assertEqual(list(back.ee_quaternion), [0.0, 1.0, 0.0, 0.0])
        self.assertFalse(back.position_only)
        self.assertEqual(back.duration_s, 2.0)
        free = goal_v2_t.decode(pose_goal("ee", [0, 0, 1], position_only=True).encode())
        self.assertTrue(free.position_only)
        self.assertEqual(list(free.ee_quaternion), [1.0, 0.0, 0.0, 0.0])
        with self.assertRaisesRegex(ValueError, "give quaternion"):
            pose_goal("ee", [0, 0, 1])
        with self.assertRaisesRegex(ValueError, "leave out quaternion"):
            pose_goal("ee", [0, 0, 1], (1, 0, 0, 0), position_only=True)
        with self.assertRaisesRegex(ValueError, "position has 2 values"):
            pose_goal("ee", [0, 0], (1, 0, 0, 0))
        with self.assertRaisesRegex(ValueError, "quaternion has 3 values"):
            pose_goal("ee", [0, 0, 1], (1, 0, 0))


class SceneMessages(unittest.TestCase):
    """Goals with tolerances, payloads and mesh obstacles, encoded as the daemon reads them."""

    def test_joint_tolerances_make_a_goal_v3(self):
        goal = joint_goal({"joint1": 0.5, "joint2": -0.2}, goal_id=45,
                          tolerance={"joint2": 1e-4})
        back = goal_v3_t.decode(goal.encode())
        self.assertEqual(list(back.joint_name), ["joint1", "joint2"])
        self.assertEqual(list(back.joint_tolerance), [0.0, 1e-4])
        with self.assertRaisesRegex(ValueError, "'elbow', a joint the goal does not name"):
            joint_goal({"joint1": 0.5}, tolerance={"elbow": 0.1})
        with self.assertRaisesRegex(ValueError, "tolerances need the joints by name"):
            joint_goal([0.5, 0.2], tolerance={"joint1": 0.1})

    def test_pose_tolerances_make_a_goal_v3(self):
        goal = pose_goal("ee", (0, 0, 1.5), position_only=True, position_tolerance=0.03)
        back = goal_v3_t.decode(goal.encode())
        self.assertEqual(back.position_tolerance_m, 0.03)
        self.assertEqual(back.orientation_tolerance_rad, 0.0)
        self.assertTrue(back.position_only)
        # Without tolerances it stays a goal_v2_t.
        goal_v2_t.decode(pose_goal("ee", (0, 0, 1.5), position_only=True).encode())

    def test_payload_and_detach(self):
        back = payload_t.decode(payload("ee", 1.5, (0.1, 0.2, 0.3), (0, 0, 0.05)).encode())
        self.assertEqual(back.action, payload_t.ATTACH)
        self.assertEqual(back.frame, "ee")
        self.assertEqual(back.mass_kg, 1.5)
        self.assertEqual(list(back.size), [0.1, 0.2, 0.3])
        self.assertEqual(list(back.offset), [0.0, 0.0, 0.05])
        self.assertEqual(payload_t.decode(detach_payload().encode()).action, payload_t.DETACH)
        with self.assertRaisesRegex(ValueError, "payload: size has 2 values"):
            payload("ee", 1.0, (0.1, 0.2))

    def test_mesh_obstacle(self):
        msg = mesh_obstacle("part", "meshes/part.obj", (0.5, 0, 1), scale=(2, 2, 2),
                            source="perception")
        back = mesh_obstacle_list_t.decode(msg.encode())
        self.assertEqual(back.source, "perception")
        self.assertEqual(back.num_obstacles, 1)
        o = back.obstacles[0]
        self.assertEqual((o.id, o.mesh, o.action), ("part", "meshes/part.obj",
                                                    mesh_obstacle_t.ADD_OR_MOVE))
        self.assertEqual(list(o.scale), [2.0, 2.0, 2.0])
        self.assertEqual(list(o.quaternion), [1.0, 0.0, 0.0, 0.0])
        gone = mesh_obstacle_list_t.decode(mesh_obstacle("part", "", (0, 0, 0),
                                                         remove=True).encode())
        self.assertEqual(gone.obstacles[0].action, mesh_obstacle_t.REMOVE)


class Binding(unittest.TestCase):
    def setUp(self):
        self.lcm = Lcm("memq://")
        self.received = []

    def tearDown(self):
        self.lcm.close()

    def on_message(self, channel, data):
        self.received.append((channel, data))

    def test_publish_reaches_matching_subscriptions_only(self):
        self.lcm.subscribe("RR_.*", self.on_message)
        self.lcm.publish("IIWA_PLAN", b"not for RR")
        self.lcm.publish("RR_PLAN", b"\x00binary\xff")
        self.assertTrue(self.lcm.handle(1.0))
        while self.lcm.handle(0.1):  # memq may or may not queue the unmatched message
            pass
        self.assertEqual(self.received, [("RR_PLAN", b"\x00binary\xff")])

    def test_timeout_and_unsubscribe(self):
        subscription = self.lcm.subscribe("A", self.on_message)
        start = time.monotonic()
        self.assertFalse(self.lcm.handle(0.05))
        self.assertGreaterEqual(time.monotonic() - start, 0.04)
        self.lcm.unsubscribe(subscription)
        self.lcm.publish("A", b"x")
        self.lcm.handle(0.05)
        self.assertEqual(self.received, [])
        with self.assertRaises(LcmError):
            self.lcm.unsubscribe(subscription)

    def test_handler_exception_is_raised_by_handle(self):
        def failing(_channel, _data):
            raise KeyError("from the handler")

        self.lcm.subscribe("A", failing)
        self.lcm.publish("A", b"x")
        with self.assertRaises(KeyError):
            self.lcm.handle(1.0)
        # The binding is still usable afterwards.
        self.lcm.subscribe("B", self.on_message)
        self.lcm.publish("B", b"y")
        self.lcm.handle(1.0)
        self.assertEqual(self.received, [("B", b"y")])

    def test_bad_url_and_closed_instance(self):
        with self.assertRaisesRegex(LcmError, "udpm://300.0.0.1:7667"):
            Lcm("udpm://300.0.0.1:7667")
        self.lcm.close()
        self.lcm.close()
        with self.assertRaisesRegex(LcmError, "closed"):
            self.lcm.publish("A", b"x")


class Client(unittest.TestCase):
    def setUp(self):
        self.client = PlannerClient("RR", "memq://")

    def tearDown(self):
        self.client.close()

    def test_waits_for_the_plan_of_its_goal(self):
        # memq: the client's own connection carries the plans, queued before the wait.
        self.client.lcm.publish("RR_PLAN", empty_plan(6).encode())
        self.client.lcm.publish("RR_PLAN", empty_plan(7).encode())
        self.client.lcm.publish("RR_PLAN", empty_plan(8).encode())
        self.assertEqual(self.client.wait_for_plan(7, 5.0).goal_id, 7)
        self.assertEqual(self.client.wait_for_plan(8, 5.0).goal_id, 8)

    def test_no_answer_is_a_timeout(self):
        with self.assertRaisesRegex(TimeoutError, "goal 3 on RR_PLAN"):
            self.client.plan(joint_goal([0.1, 0.2], goal_id=3), timeout_s=0.1)

    def test_a_foreign_message_on_the_plan_channel_is_refused(self):
        self.client.lcm.publish("RR_PLAN", b"12345678 not a plan")
        with self.assertRaisesRegex(ValueError, "RR_PLAN: a message that is not a kinograph plan_t"):
            self.client.wait_for_plan(1, 5.0)


if __name__ == "__main__":
    unittest.main()

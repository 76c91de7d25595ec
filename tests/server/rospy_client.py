"""A ROS 1 client written with rospy and actionlib (Debian's packages), run against
`partsim serve --ros1`. Usage: rospy_client.py ROBOT (ROS_MASTER_URI names the master; the
generated control_msgs and partsim_msgs modules must be on PYTHONPATH).
Prints one JSON line with what it measured; exits 0 when every check passed."""
import json
import os
import sys
import threading
import time

import actionlib
import rospy
from actionlib_msgs.msg import GoalStatus
from control_msgs.msg import (FollowJointTrajectoryAction, FollowJointTrajectoryGoal,
                              FollowJointTrajectoryResult, JointTolerance)
from partsim_msgs.srv import PlanMotion, PlanMotionRequest, Step
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

robot = sys.argv[1] if len(sys.argv) > 1 else "panda"
result = {"checks": []}


def fail(why):
    result["error"] = why
    print(json.dumps(result))
    sys.stdout.flush()
    rospy.signal_shutdown("failed")
    sys.exit(1)


def check(cond, what):
    if not cond:
        fail(what)
    result["checks"].append(what)


def timed_out():
    result["error"] = "timed out"
    print(json.dumps(result))
    sys.stdout.flush()
    os._exit(1)


watchdog = threading.Timer(120.0, timed_out)
watchdog.daemon = True
watchdog.start()
rospy.init_node("partsim_rospy_client", anonymous=True, disable_signals=True)
check(rospy.get_param("/use_sim_time", False) is True, "/use_sim_time is true")

# topics and types, as the master lists them
published = dict(rospy.get_published_topics())
prefix = "/" + robot
for topic, type_ in [("/clock", "rosgraph_msgs/Clock"), ("/joint_states", "sensor_msgs/JointState"),
                     ("/tf", "tf2_msgs/TFMessage"),
                     (prefix + "/joint_trajectory_controller/follow_joint_trajectory/status",
                      "actionlib_msgs/GoalStatusArray")]:
    check(published.get(topic) == type_, "%s is published as %s" % (topic, type_))

# rates of /clock and /joint_states over two wall-clock seconds
lock = threading.Lock()
clocks, states, last = [], [], {}


def on_clock(m):
    with lock:
        clocks.append(m.clock.to_sec())


def on_state(m):
    with lock:
        states.append(m.header.stamp.to_sec())
        last["msg"] = m


rospy.Subscriber("/clock", Clock, on_clock, queue_size=1000)
rospy.Subscriber("/joint_states", JointState, on_state, queue_size=1000)


def wait_for(pred, what, seconds=60.0):
    """Polls pred() until it holds; fails, naming `what`, after `seconds` (a loaded 2-core
    machine needs far less)."""
    deadline = time.monotonic() + seconds
    while not pred():
        if time.monotonic() > deadline:
            check(False, "waited %.0f s for %s" % (seconds, what))
        time.sleep(0.02)


def counts():
    with lock:
        return len(clocks), len(states)


wait_for(lambda: min(counts()) > 0, "the first /clock and /joint_states messages")
with lock:
    del clocks[:], states[:]
# the rates over at least 2 s and 1 s of simulated time (which a loaded machine takes longer
# for), per simulated second: what the node publishes, whatever the machine's load
t0 = time.monotonic()
wait_for(lambda: time.monotonic() - t0 >= 2.0 and min(counts()) > 10 and
         states[-1] - states[0] >= 1.0 and clocks[-1] - clocks[0] >= 1.0,
         "1 s of simulated time on /clock and /joint_states")
wall = time.monotonic() - t0
with lock:
    result["clock_hz"] = len(clocks) / wall
    result["joint_states_hz"] = len(states) / wall
    result["sim_seconds_per_wall_second"] = (states[-1] - states[0]) / wall
    result["clock_per_sim_second"] = (len(clocks) - 1) / (clocks[-1] - clocks[0])
    result["joint_states_per_sim_second"] = (len(states) - 1) / (states[-1] - states[0])
    check(all(b >= a for a, b in zip(clocks, clocks[1:])), "/clock is monotonic")
# rospy follows the simulation's clock
check(abs(rospy.get_time() - clocks[-1]) < 1.0, "rospy time follows /clock")


def positions(names):
    with lock:
        m = last["msg"]
    return [m.position[m.name.index(n)] for n in names]


def wait_until_at(names, goal, seconds):
    err = float("inf")
    t = time.monotonic()
    while time.monotonic() - t < seconds:
        err = max(abs(a - b) for a, b in zip(positions(names), goal))
        if err < 0.01:
            break
        time.sleep(0.05)
    return err


arm = ["%s_joint%d" % (robot, i) for i in range(1, 8)]

# a JointTrajectory on the command topic
start = positions(arm)
goal = [q + 0.1 for q in start]
traj = JointTrajectory()
traj.joint_names = arm
traj.points = [JointTrajectoryPoint(positions=goal, time_from_start=rospy.Duration(1.0))]
pub = rospy.Publisher(prefix + "/joint_trajectory_controller/command", JointTrajectory,
                      queue_size=1, latch=True)
pub.publish(traj)
result["topic_trajectory_error"] = wait_until_at(arm, goal, 60.0)
check(result["topic_trajectory_error"] < 0.01, "the command-topic trajectory reached its goal")

# follow_joint_trajectory through actionlib
client = actionlib.SimpleActionClient(
    prefix + "/joint_trajectory_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
check(client.wait_for_server(rospy.Duration(20.0)), "the action server is up")
feedback = []
start = positions(arm)
goal = [q - 0.15 for q in start]
g = FollowJointTrajectoryGoal()
g.trajectory.joint_names = arm
g.trajectory.points = [
    JointTrajectoryPoint(positions=[(a + b) / 2 for a, b in zip(start, goal)],
                         time_from_start=rospy.Duration(0.75)),
    JointTrajectoryPoint(positions=goal, time_from_start=rospy.Duration(1.5))]
g.goal_tolerance = [JointTolerance(name=n, position=0.01) for n in arm]
g.goal_time_tolerance = rospy.Duration(2.0)
client.send_goal(g, feedback_cb=lambda f: feedback.append(f))
check(client.wait_for_result(rospy.Duration(30.0)), "the action finished")
res = client.get_result()
result["action_state"] = GoalStatus.to_string(client.get_state()) \
    if hasattr(GoalStatus, "to_string") else client.get_state()
result["action_error_string"] = res.error_string if res else None
check(client.get_state() == GoalStatus.SUCCEEDED, "follow_joint_trajectory SUCCEEDED")
check(res.error_code == FollowJointTrajectoryResult.SUCCESSFUL, "error_code SUCCESSFUL")
result["action_feedback_messages"] = len(feedback)
check(len(feedback) > 5 and list(feedback[-1].joint_names) == [
    n for n in feedback[-1].joint_names], "feedback arrived")
result["action_final_error"] = max(abs(a - b) for a, b in zip(positions(arm), goal))
check(result["action_final_error"] < 0.02, "the action's goal was reached")

# a goal naming a joint the robot lacks is rejected with INVALID_JOINTS
bad = FollowJointTrajectoryGoal()
bad.trajectory.joint_names = ["no_such_joint"]
bad.trajectory.points = [JointTrajectoryPoint(positions=[0.0], time_from_start=rospy.Duration(1))]
client.send_goal(bad)
client.wait_for_result(rospy.Duration(10.0))
check(client.get_state() == GoalStatus.REJECTED, "a goal with an unknown joint is REJECTED")
check(client.get_result().error_code == FollowJointTrajectoryResult.INVALID_JOINTS,
      "error_code INVALID_JOINTS")

# a goal preempted by a newer one
long_goal = FollowJointTrajectoryGoal()
long_goal.trajectory.joint_names = arm[:1]
here = positions(arm[:1])[0]
long_goal.trajectory.points = [JointTrajectoryPoint(positions=[here + 0.3],
                                                    time_from_start=rospy.Duration(4.0))]
first = actionlib.SimpleActionClient(
    prefix + "/joint_trajectory_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
first.wait_for_server(rospy.Duration(10.0))
first.send_goal(long_goal)
wait_for(lambda: first.get_state() == GoalStatus.ACTIVE, "the 4 s goal to become ACTIVE")
client.send_goal(g)  # back to the previous goal
first.wait_for_result(rospy.Duration(10.0))
check(first.get_state() == GoalStatus.PREEMPTED, "a goal replaced by a newer one is PREEMPTED")
client.wait_for_result(rospy.Duration(30.0))
check(client.get_state() == GoalStatus.SUCCEEDED, "the newer goal SUCCEEDED")

# motion planning as a service
rospy.wait_for_service(prefix + "/plan", 10.0)
plan = rospy.ServiceProxy(prefix + "/plan", PlanMotion)
names = [n for n in last["msg"].name if n.startswith(robot)]
req = PlanMotionRequest()
target = positions(names)
target[0] += 0.4
target[3] += 0.3
req.joint_goal = target
req.execute = True
r = plan(req)
result["plan_success"] = r.success
result["plan_time"] = r.planning_time
check(r.success, "the plan service found a plan: " + r.message)
check(len(r.trajectory.points) >= 2 and list(r.trajectory.joint_names) == names,
      "the plan comes as a trajectory over the robot's joints")
result["plan_final_error"] = wait_until_at(names[:7], target[:7], 60.0)
check(result["plan_final_error"] < 0.02, "the planned motion was executed")
req.joint_goal = [0.0]
check(not plan(req).success, "a joint goal of the wrong size fails")

# pause, step exactly, resume
rospy.wait_for_service("/partsim/pause", 5.0)
rospy.ServiceProxy("/partsim/pause", Empty)()


def last_clock():
    with lock:
        return clocks[-1]


def still(seconds=1.0):
    """Whether /clock stays unchanged for `seconds` (it comes at every step while running)."""
    value, since = last_clock(), time.monotonic()
    while time.monotonic() - since < seconds:
        time.sleep(0.02)
        if last_clock() != value:
            return False
    return True


wait_for(still, "paused: the clock to stand still for 1 s")
before = last_clock()
steps = rospy.ServiceProxy("/partsim/step", Step)(25)
wait_for(lambda: last_clock() >= before + 25 * 0.002 - 1e-9, "/clock after 25 steps")
time.sleep(0.3)  # and no more
with lock:
    result["stepped_seconds"] = clocks[-1] - before
check(abs(result["stepped_seconds"] - 25 * 0.002) < 1e-6, "step 25 advances 25 steps")
rospy.ServiceProxy("/partsim/resume", Empty)()

print(json.dumps(result))
sys.stdout.flush()
rospy.signal_shutdown("done")
sys.exit(0)

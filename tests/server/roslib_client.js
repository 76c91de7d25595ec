// A rosbridge client written with roslib (npm), the JavaScript library ROS web tools use, run
// against `partsim serve`. Usage: node roslib_client.js PORT ROBOT
// Prints one JSON line with what it measured; exits 0 when every check passed.
import { Ros, Topic, Service } from 'roslib';

const port = process.argv[2];
const robot = process.argv[3] || 'panda';
const result = { connected: false, checks: {} };
const fail = (why) => {
  result.error = why;
  console.log(JSON.stringify(result));
  process.exit(1);
};
// every wait below has its own deadline; this one only ends a client that hangs
setTimeout(() => fail('timed out'), 240000);

const ros = new Ros({ url: `ws://127.0.0.1:${port}` });
ros.on('error', (e) => fail('connection error: ' + e));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
/** Polls pred() until it holds; fails naming `what` after `ms` (a loaded machine needs less). */
const waitFor = async (pred, what, ms = 60000) => {
  const t = Date.now();
  while (!pred()) {
    if (Date.now() - t > ms) fail(`waited ${ms / 1000} s for ${what}`);
    await sleep(20);
  }
};
const stampSecs = (s) => s.secs + s.nsecs * 1e-9;

ros.on('connection', async () => {
  result.connected = true;
  // topics and types through rosapi
  const topics = await new Promise((res, rej) => ros.getTopics(res, rej));
  result.topics = topics.topics;
  const trajTopic = `/${robot}/joint_trajectory_controller/command`;
  for (const t of ['/clock', '/joint_states', '/tf', trajTopic])
    if (!topics.topics.includes(t)) fail('rosapi/topics lacks ' + t);
  result.joint_states_type = await new Promise((res, rej) => ros.getTopicType('/joint_states', res, rej));
  if (result.joint_states_type !== 'sensor_msgs/JointState') fail('wrong /joint_states type');

  // rates of /clock and /joint_states over at least two wall-clock seconds and one simulated one
  let clocks = [], states = [], last = null;
  const clock = new Topic({ ros, name: '/clock', messageType: 'rosgraph_msgs/Clock' });
  const js = new Topic({ ros, name: '/joint_states', messageType: 'sensor_msgs/JointState' });
  clock.subscribe((m) => clocks.push(stampSecs(m.clock)));
  js.subscribe((m) => {
    states.push(stampSecs(m.header.stamp));
    last = m;
  });
  await waitFor(() => clocks.length > 0 && states.length > 0, 'the first /clock and /joint_states');
  clocks = [];
  states = [];
  const t0 = Date.now();
  const simSpan = (a) => (a.length > 1 ? a[a.length - 1] - a[0] : 0);
  await waitFor(() => Date.now() - t0 >= 2000 && clocks.length > 10 && states.length > 10 &&
                      simSpan(clocks) >= 1 && simSpan(states) >= 1,
                '1 s of simulated time on /clock and /joint_states');
  const wall = (Date.now() - t0) / 1000;
  result.clock_hz = clocks.length / wall;
  result.joint_states_hz = states.length / wall;
  result.sim_seconds_per_wall_second = simSpan(states) / wall;
  // per simulated second: what the server publishes for each step, whatever the machine's load
  result.clock_per_sim_second = (clocks.length - 1) / simSpan(clocks);
  result.joint_states_per_sim_second = (states.length - 1) / simSpan(states);
  for (let i = 1; i < clocks.length; ++i)
    if (clocks[i] < clocks[i - 1]) fail('/clock went backwards');
  if (!last || last.name.length !== last.position.length || last.velocity.length !== last.name.length ||
      last.effort.length !== last.name.length || typeof last.header.frame_id !== 'string')
    fail('malformed /joint_states');

  // a trajectory for the robot's joints: every arm joint moves by 0.15 over 1.5 s
  const names = last.name.filter((n) => n.startsWith(robot)).slice(0, 7);
  const start = names.map((n) => last.position[last.name.indexOf(n)]);
  const goal = start.map((q) => q + 0.15);
  const traj = new Topic({ ros, name: trajTopic, messageType: 'trajectory_msgs/JointTrajectory' });
  traj.publish({
    header: { seq: 0, stamp: { secs: 0, nsecs: 0 }, frame_id: '' },
    joint_names: names,
    points: [
      { positions: start.map((q, i) => q + 0.075), velocities: [], accelerations: [], effort: [],
        time_from_start: { secs: 0, nsecs: 750000000 } },
      { positions: goal, velocities: [], accelerations: [], effort: [],
        time_from_start: { secs: 1, nsecs: 500000000 } },
    ],
  });
  let err = Infinity;
  const tSend = Date.now();
  while (Date.now() - tSend < 60000) {
    await sleep(100);
    err = Math.max(...names.map((n, i) => Math.abs(last.position[last.name.indexOf(n)] - goal[i])));
    if (err < 0.01 && Date.now() - tSend > 1500) break;
  }
  result.trajectory_joints = names;
  result.trajectory_final_error = err;
  result.trajectory_seconds = (Date.now() - tSend) / 1000;
  if (!(err < 0.01)) fail('trajectory not executed: error ' + err);

  // CBOR subscriptions: binary frames that roslib decodes; uint8[] arrives as bytes
  const cborStates = new Topic({ ros, name: '/joint_states', messageType: 'sensor_msgs/JointState',
                                 compression: 'cbor', throttle_rate: 100 });
  const cborState = await new Promise((res) => cborStates.subscribe(res));
  cborStates.unsubscribe();
  if (!Array.isArray(cborState.name) || cborState.position.length !== cborState.name.length)
    fail('malformed CBOR /joint_states');
  const image = new Topic({ ros, name: '/front_camera/image_raw', messageType: 'sensor_msgs/Image',
                            compression: 'cbor' });
  const im = await new Promise((res) => image.subscribe(res));
  image.unsubscribe();
  result.cbor_image = { width: im.width, height: im.height, bytes: im.data.length,
                        is_bytes: im.data instanceof Uint8Array };
  if (!(im.data instanceof Uint8Array) || im.data.length !== im.width * im.height * 3)
    fail('CBOR image data is not width*height*3 bytes');

  // motion planning as a service: the first arm joint turns by 0.3 rad, planned and executed
  const plan = new Service({ ros, name: `/${robot}/plan`, serviceType: 'partsim_msgs/PlanMotion' });
  const allNames = last.name.filter((n) => n.startsWith(robot));
  const target = allNames.map((n) => last.position[last.name.indexOf(n)]);
  target[0] += 0.3;
  const planned = await new Promise((res, rej) =>
    plan.callService({ joint_goal: target, execute: true }, res, rej));
  result.plan = { success: planned.success, planning_time: planned.planning_time,
                  points: planned.trajectory.points.length };
  if (!planned.success) fail('plan failed: ' + planned.message);
  let planErr = Infinity;
  const tPlan = Date.now();
  while (Date.now() - tPlan < 60000) {
    await sleep(100);
    planErr = Math.abs(last.position[last.name.indexOf(allNames[0])] - target[0]);
    if (planErr < 0.01) break;
  }
  result.plan_final_error = planErr;
  if (!(planErr < 0.01)) fail('planned motion not executed: error ' + planErr);

  // the server's own counters (command latency in steps)
  const stats = new Service({ ros, name: '/partsim/stats', serviceType: 'std_srvs/Trigger' });
  result.stats = await new Promise((res, rej) => stats.callService({}, res, rej));
  console.log(JSON.stringify(result));
  process.exit(0);
});

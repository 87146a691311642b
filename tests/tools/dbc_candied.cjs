// dbc_candied.cjs: decodes a daemon --can-log with protocol/odometry.dbc through the npm DBC
// library `candied` (a second client that knows nothing of the firmware's source, beside
// dbc_decode.py) and checks the last frames against odometryd --json.
// usage: node dbc_candied.cjs NODE_MODULES_DIR DBC CAN_LOG JSON      exit 0 ok, 1 mismatch
'use strict';
const fs = require('fs');
const path = require('path');
const [modules, dbcPath, logPath, jsonPath] = process.argv.slice(2);
const { Dbc, Can } = require(path.resolve(modules, 'candied'));

const can = new Can();
can.database = new Dbc().load(fs.readFileSync(dbcPath, 'utf8'));
const want = JSON.parse(fs.readFileSync(jsonPath, 'utf8'));
const last = {};  // message name -> {signal: value} of its last frame
const seen = {};
let frames = 0;
let unknown = 0;
for (const line of fs.readFileSync(logPath, 'utf8').split('\n')) {
  const m = /^\(\d+\.\d{6}\) \S+ ([0-9A-F]{3})#([0-9A-F]*)$/.exec(line);
  if (!m) continue;
  ++frames;
  const bytes = (m[2].match(/../g) || []).map((h) => parseInt(h, 16));
  const msg = can.decode(can.createFrame(parseInt(m[1], 16), bytes));
  if (!msg) {
    ++unknown;
    continue;
  }
  const values = {};
  for (const [name, s] of msg.boundSignals) values[name] = s.value;
  last[msg.name] = values;
  seen[msg.name] = (seen[msg.name] || 0) + 1;
}

const problems = [];
const expect = (ok, what) => { if (!ok) problems.push(what); };
const near = (a, b, tol) => typeof a === 'number' && Math.abs(a - b) <= tol;
expect(unknown === 0, `${unknown} frames not in the DBC`);
expect(frames === want.can.sent, `frames ${frames} != sent ${want.can.sent}`);
for (const name of ['PoseX', 'PoseYTheta', 'Velocity', 'Uncertainty', 'Status', 'Timing'])
  expect(seen[name] > 0, `no ${name} frame decoded`);
// Every signal of every message is decoded (candied 2.2.0 dropped those whose factor was
// written 1e-05 or 1e-06).
const signals = {
  PoseX: ['x', 'seq'], PoseYTheta: ['y', 'theta', 'seq'], Velocity: ['v', 'omega', 'seq'],
  Uncertainty: ['sigma_x', 'sigma_y', 'sigma_theta', 'rho_xy', 'seq'],
  Status: ['encoder_flags', 'calibration_state', 'stopping', 'set_pose_ack', 'missed_deadlines',
           'uptime'],
  Timing: ['wakeup_p99', 'wakeup_max', 'compute_max', 'tx_dropped'],
};
for (const [msg, names] of Object.entries(signals))
  for (const s of names) expect(last[msg] && typeof last[msg][s] === 'number', `${msg}.${s} missing`);
if (problems.length === 0) {
  // The final frames equal the --json summary within the protocol's resolution.
  expect(near(last.PoseX.x, want.x, 0.5e-4 + 1e-9), `x ${last.PoseX.x} != ${want.x}`);
  expect(near(last.PoseYTheta.y, want.y, 0.5e-4 + 1e-9), `y ${last.PoseYTheta.y} != ${want.y}`);
  expect(near(last.PoseYTheta.theta, want.theta, 0.5e-4 + 1e-9) ||
             near(Math.abs(last.PoseYTheta.theta), Math.PI, 1e-4),
         `theta ${last.PoseYTheta.theta} != ${want.theta}`);
  expect(last.Status.stopping === 1, 'last status is not the stopping one');
  expect(last.Status.calibration_state === want.calibration_state, 'calibration_state differs');
  expect(last.Status.missed_deadlines === want.missed_deadlines, 'missed_deadlines differs');
  expect(last.Status.uptime === Math.floor(want.loop_time), 'uptime differs');
  expect(last.Uncertainty.sigma_theta > 0, 'sigma_theta not positive');
}
for (const p of problems) console.error(`dbc_candied: ${p}`);
console.log(JSON.stringify({ frames, unknown, messages: seen }));
process.exit(problems.length === 0 ? 0 : 1);

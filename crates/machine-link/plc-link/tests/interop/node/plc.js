// A shovel PLC nobody here wrote: a small node-opcua server on the model of
// docs/machine-link.md, for `autoshovel drive` to run against.
//
// Usage: node plc.js PORT PKI_ROOT PASSWORD X Y THETA (NODE_PATH: node-opcua)
//
// Basic256Sha256 SignAndEncrypt only, the PLC's certificate from pki/plc,
// the workstation's trusted, the operator's user name and password needed.
// An ideal crawler (no slip, no noise; 1.5 m gauge, sprocket 0.3 m, gear
// 38, 3000 rpm, 6000 rpm/s) at 10 ms steps, RTK fixes at 10 Hz with their
// own timestamps, a 250 ms heartbeat watchdog that latches a fault and ends
// the lock, an instance id, and control on OPC 10000-100's LockingServices
// (Shovel.Control), bound to the claiming session: setpoints are obeyed
// only while a session holds control. No Simulator folder: it is a PLC.
// Prints "ready" once listening and runs until killed.
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const {
  OPCUAServer,
  OPCUACertificateManager,
  MessageSecurityMode,
  SecurityPolicy,
  Variant,
  DataType,
  StatusCodes,
} = require("node-opcua");
const { ownPem } = require("./pem.js");

const NS_URI = "urn:autoshovel:shovel-plc";
const [GAUGE, R_S, GEAR, MAX_RPM, MAX_ACC] = [1.5, 0.3, 38.0, 3000.0, 6000.0];
const K = (2 * Math.PI * R_S) / (60 * GEAR); // m/s per rpm

async function main() {
  const [port, pki, password, x0, y0, th0] = process.argv.slice(2);
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "node-plc-"));
  const manager = new OPCUACertificateManager({
    rootFolder: path.join(scratch, "pki"),
    automaticallyAcceptUnknownCertificate: false,
  });
  await manager.initialize();
  await manager.trustCertificate(fs.readFileSync(path.join(pki, "workstation", "own", "cert.der")));
  const { cert, key } = ownPem(pki, "plc", scratch);

  const server = new OPCUAServer({
    port: Number(port),
    securityPolicies: [SecurityPolicy.Basic256Sha256],
    securityModes: [MessageSecurityMode.SignAndEncrypt],
    allowAnonymous: false,
    certificateFile: cert,
    privateKeyFile: key,
    serverCertificateManager: manager,
    userManager: { isValidUser: (u, p) => u === "operator" && p === password },
    serverInfo: { applicationUri: "urn:autoshovel:plc-sim", applicationName: { text: "node-opcua shovel PLC" } },
  });
  await server.initialize();
  const space = server.engine.addressSpace;
  const ns = space.registerNamespace(NS_URI);

  // The machine at rest at the given pose (θ from east, counter-clockwise).
  const st = {
    x: Number(x0), y: Number(y0), th: Number(th0), nl: 0, nr: 0, wantL: 0, wantR: 0,
    hb: null, hbAt: null, fault: null, holder: null,
    fix: { east: 0, north: 0, heading: 0, stamp: new Date(Date.UTC(1601, 0, 1)), quality: 0 },
    clock: new Date(Date.UTC(1601, 0, 1)),
  };
  const instance = `node-${process.pid}-${Date.now()}`;

  const folders = {};
  function folder(p) {
    if (folders[p]) return folders[p];
    const i = p.lastIndexOf(".");
    const parent = i < 0 ? space.rootFolder.objects : folder(p.slice(0, i));
    folders[p] = ns.addFolder(parent, { nodeId: `s=${p}`, browseName: p.slice(i + 1) });
    return folders[p];
  }
  function variable(p, dataType, get, set) {
    const i = p.lastIndexOf(".");
    const opts = {
      organizedBy: folder(p.slice(0, i)),
      nodeId: `s=${p}`,
      browseName: p.slice(i + 1),
      dataType,
      value: { get: () => new Variant({ dataType: DataType[dataType] || DataType.Double, value: get() }) },
    };
    if (set) {
      opts.accessLevel = "CurrentRead | CurrentWrite";
      opts.userAccessLevel = "CurrentRead | CurrentWrite";
      opts.value.set = (v) => set(v.value);
    }
    ns.addVariable(opts);
  }
  const setpoint = (side) => (v) => {
    if (typeof v !== "number" || !Number.isFinite(v) || Math.abs(v) > MAX_RPM) {
      latch(3, `${side} setpoint ${v} rpm refused`);
      return StatusCodes.BadOutOfRange;
    }
    if (st.holder === null) return StatusCodes.BadRequiresLock;
    if (side === "left") st.wantL = v;
    else st.wantR = v;
    return StatusCodes.Good;
  };
  function latch(code, text) {
    if (st.fault === null) st.fault = { code, text };
    st.wantL = st.wantR = 0;
  }
  const readings = (n) => [Math.abs(n) * 4 / 120, Math.abs(n) > 1 ? 12 : 0, 400 * Math.min(1, Math.abs(n) * 4 / 120 / 50)];
  variable("Shovel.Crawler.Left.SpeedSetpoint", "Double", () => st.wantL, setpoint("left"));
  variable("Shovel.Crawler.Left.Speed", "Double", () => st.nl);
  variable("Shovel.Crawler.Left.Frequency", "Double", () => readings(st.nl)[0]);
  variable("Shovel.Crawler.Left.Current", "Double", () => readings(st.nl)[1]);
  variable("Shovel.Crawler.Left.Voltage", "Double", () => readings(st.nl)[2]);
  variable("Shovel.Crawler.Right.SpeedSetpoint", "Double", () => st.wantR, setpoint("right"));
  variable("Shovel.Crawler.Right.Speed", "Double", () => st.nr);
  variable("Shovel.Crawler.Right.Frequency", "Double", () => readings(st.nr)[0]);
  variable("Shovel.Crawler.Right.Current", "Double", () => readings(st.nr)[1]);
  variable("Shovel.Crawler.Right.Voltage", "Double", () => readings(st.nr)[2]);
  variable("Shovel.Rtk.East", "Double", () => st.fix.east);
  variable("Shovel.Rtk.North", "Double", () => st.fix.north);
  variable("Shovel.Rtk.Heading", "Double", () => st.fix.heading);
  variable("Shovel.Rtk.FixQuality", "Byte", () => st.fix.quality);
  variable("Shovel.Rtk.Timestamp", "DateTime", () => st.fix.stamp);
  variable("Shovel.Clock", "DateTime", () => st.clock);
  variable("Shovel.Workstation.Heartbeat", "UInt32", () => st.hb || 0, (v) => {
    if (st.holder === null) return StatusCodes.BadRequiresLock;
    if (v !== st.hb) {
      st.hb = v;
      st.hbAt = Date.now();
    }
    return StatusCodes.Good;
  });
  variable("Shovel.Mode", "Byte", () => 1);
  variable("Shovel.Fault.Active", "Boolean", () => st.fault !== null);
  variable("Shovel.Fault.Code", "UInt32", () => (st.fault ? st.fault.code : 0));
  variable("Shovel.Fault.Text", "String", () => (st.fault ? st.fault.text : ""));
  variable("Shovel.Limits.MotorMaxSpeed", "Double", () => MAX_RPM);
  variable("Shovel.Limits.MotorMaxAcceleration", "Double", () => MAX_ACC);
  variable("Shovel.InstanceId", "String", () => instance);
  variable("Shovel.Control.Locked", "Boolean", () => st.holder !== null);
  variable("Shovel.Control.LockingClient", "String", () => st.holder || "");
  variable("Shovel.Control.LockingUser", "String", () => (st.holder ? "operator" : ""));
  variable("Shovel.Control.RemainingLockTime", "Duration", () =>
    st.holder && st.hbAt ? Math.max(0, 250 - (Date.now() - st.hbAt)) : 0);

  const control = folder("Shovel.Control");
  const int32 = (v) => ({ statusCode: StatusCodes.Good, outputArguments: [{ dataType: DataType.Int32, value: v }] });
  const methods = {
    InitLock: (who) => {
      if (st.holder !== null && st.holder !== who) return int32(-1);
      st.holder = who;
      st.hbAt = Date.now();
      return int32(0);
    },
    RenewLock: (who) => {
      if (st.holder === null) return int32(-1);
      if (st.holder !== who) return { statusCode: StatusCodes.BadLocked };
      st.hbAt = Date.now();
      return int32(0);
    },
    ExitLock: (who) => {
      if (st.holder === null) return int32(-1);
      if (st.holder !== who) return { statusCode: StatusCodes.BadLocked };
      st.holder = null;
      latch(5, "control released");
      return int32(0);
    },
    BreakLock: () => {
      if (st.holder === null) return int32(-1);
      st.holder = null;
      latch(5, "control broken");
      return int32(0);
    },
  };
  for (const [name, f] of Object.entries(methods)) {
    const method = ns.addMethod(control, {
      nodeId: `s=Shovel.Control.${name}`,
      browseName: name,
      inputArguments: name === "InitLock" ? [{ name: "Context", dataType: DataType.String }] : [],
      outputArguments: [{ name: `${name}Status`, dataType: DataType.Int32 }],
    });
    method.bindMethod((args, context, callback) => {
      const who = context.session ? context.session.nodeId.toString() : "unknown";
      callback(null, f(who));
    });
  }
  const ack = ns.addMethod(folder("Shovel.Fault"), { nodeId: "s=Shovel.Fault.Acknowledge", browseName: "Acknowledge" });
  ack.bindMethod((args, context, callback) => {
    if (Math.abs(st.nl) > 1 || Math.abs(st.nr) > 1) return callback(null, { statusCode: StatusCodes.BadInvalidState });
    st.fault = null;
    callback(null, { statusCode: StatusCodes.Good });
  });

  await server.start();
  console.log("ready");

  let last = Date.now();
  let t = 0;
  let nextFix = 0;
  setInterval(() => {
    const now = Date.now();
    const dt = (now - last) / 1000;
    last = now;
    if (st.holder !== null && st.hbAt !== null && now - st.hbAt > 250) {
      st.holder = null;
      latch(1, "heartbeat lost");
    }
    const obey = st.fault === null && st.holder !== null && st.hb !== null;
    const [wl, wr] = obey ? [st.wantL, st.wantR] : [0, 0];
    const dn = MAX_ACC * dt;
    st.nl += Math.max(-dn, Math.min(dn, wl - st.nl));
    st.nr += Math.max(-dn, Math.min(dn, wr - st.nr));
    const [vl, vr] = [st.nl * K, st.nr * K];
    const [v, w] = [(vl + vr) / 2, (vr - vl) / GAUGE];
    st.x += v * dt * Math.cos(st.th + (w * dt) / 2);
    st.y += v * dt * Math.sin(st.th + (w * dt) / 2);
    st.th += w * dt;
    t += dt;
    st.clock = new Date(now);
    if (t >= nextFix) {
      nextFix += 0.1;
      const heading = ((((Math.PI / 2 - st.th) * 180) / Math.PI) % 360 + 360) % 360;
      st.fix = { east: st.x, north: st.y, heading, stamp: new Date(now), quality: 4 };
    }
  }, 10);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});

// An OPC UA client nobody here wrote (node-opcua, npm) against plc-sim.
//
// Usage: node client.js ENDPOINT PKI_ROOT PASSWORD
// (NODE_PATH names the node_modules holding node-opcua.)
//
// Connects with Basic256Sha256 SignAndEncrypt presenting the workstation's
// certificate (pki/workstation), trusting the PLC's (pki/plc), as the
// operator: reads the pose, writes a setpoint before and after claiming
// control (OPC 10000-100 InitLock), opens a second operator session whose
// claim and write must be refused, reads anonymously, releases control.
// Prints what it saw as JSON.
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const {
  OPCUAClient,
  OPCUACertificateManager,
  MessageSecurityMode,
  SecurityPolicy,
  AttributeIds,
  DataType,
  UserTokenType,
} = require("node-opcua");
const { ownPem } = require("./pem.js");

const NS_URI = "urn:autoshovel:shovel-plc";

async function client(endpoint, pki, scratch) {
  const manager = new OPCUACertificateManager({
    rootFolder: path.join(scratch, "node-pki"),
    automaticallyAcceptUnknownCertificate: false,
  });
  await manager.initialize();
  await manager.trustCertificate(fs.readFileSync(path.join(pki, "plc", "own", "cert.der")));
  const { cert, key } = ownPem(pki, "workstation", scratch);
  const c = OPCUAClient.create({
    applicationName: "autoshovel-workstation",
    applicationUri: "urn:autoshovel:workstation",
    securityMode: MessageSecurityMode.SignAndEncrypt,
    securityPolicy: SecurityPolicy.Basic256Sha256,
    certificateFile: cert,
    privateKeyFile: key,
    clientCertificateManager: manager,
    endpointMustExist: false,
    connectionStrategy: { maxRetry: 2, initialDelay: 100, maxDelay: 500 },
  });
  await c.connect(endpoint);
  return c;
}

async function main() {
  const [endpoint, pki, password] = process.argv.slice(2);
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "node-opcua-"));
  const out = {};
  const c = await client(endpoint, pki, scratch);
  const s = await c.createSession({ type: UserTokenType.UserName, userName: "operator", password });
  const ns = (await s.readNamespaceArray()).indexOf(NS_URI);
  const id = (x) => `ns=${ns};s=${x}`;
  const read = async (x) => (await s.read({ nodeId: id(x), attributeId: AttributeIds.Value })).value.value;
  const write = async (sess, x, v) =>
    (
      await sess.write({
        nodeId: id(x),
        attributeId: AttributeIds.Value,
        value: { value: { dataType: DataType.Double, value: v } },
      })
    ).name;
  const lock = async (sess, m, args) =>
    (
      await sess.call({
        objectId: id("Shovel.Control"),
        methodId: id(`Shovel.Control.${m}`),
        inputArguments: args,
      })
    ).outputArguments[0].value;
  out.east_m = await read("Shovel.Rtk.East");
  out.instance = await read("Shovel.InstanceId");
  out.write_unclaimed = await write(s, "Shovel.Crawler.Left.SpeedSetpoint", 12.5);
  out.init_lock = await lock(s, "InitLock", [{ dataType: DataType.String, value: "node-opcua interop" }]);
  out.locking_user = await read("Shovel.Control.LockingUser");
  out.write_claimed = await write(s, "Shovel.Crawler.Left.SpeedSetpoint", 123.5);
  const s2 = await c.createSession({ type: UserTokenType.UserName, userName: "operator", password });
  out.second_init_lock = await lock(s2, "InitLock", [{ dataType: DataType.String, value: "second" }]);
  out.second_write = await write(s2, "Shovel.Crawler.Left.SpeedSetpoint", -2000);
  await s2.close();
  const anon = await c.createSession();
  out.anonymous_read_east = (
    await anon.read({ nodeId: id("Shovel.Rtk.East"), attributeId: AttributeIds.Value })
  ).value.value;
  out.anonymous_write = await write(anon, "Shovel.Crawler.Left.SpeedSetpoint", 10);
  await anon.close();
  out.exit_lock = await lock(s, "ExitLock", []);
  await s.close();
  await c.disconnect();
  fs.rmSync(scratch, { recursive: true, force: true });
  console.log(JSON.stringify(out));
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});

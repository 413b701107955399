// A bystander nobody here wrote (node-opcua): anonymous sessions that
// connect, read the pose and disconnect, again and again, until STOP_FILE
// exists or N visits are made. Prints the number of visits made.
//
// Usage: node bystander.js ENDPOINT PKI_ROOT N STOP_FILE (NODE_PATH: node-opcua)
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
} = require("node-opcua");
const { ownPem } = require("./pem.js");

async function main() {
  const [endpoint, pki, n, stop] = process.argv.slice(2);
  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "node-bystander-"));
  const manager = new OPCUACertificateManager({
    rootFolder: path.join(scratch, "pki"),
    automaticallyAcceptUnknownCertificate: false,
  });
  await manager.initialize();
  await manager.trustCertificate(fs.readFileSync(path.join(pki, "plc", "own", "cert.der")));
  const { cert, key } = ownPem(pki, "workstation", scratch);
  let made = 0;
  while (made < Number(n) && !fs.existsSync(stop)) {
    const c = OPCUAClient.create({
      applicationName: "bystander",
      applicationUri: "urn:autoshovel:workstation",
      securityMode: MessageSecurityMode.SignAndEncrypt,
      securityPolicy: SecurityPolicy.Basic256Sha256,
      certificateFile: cert,
      privateKeyFile: key,
      clientCertificateManager: manager,
      endpointMustExist: false,
      connectionStrategy: { maxRetry: 1, initialDelay: 100, maxDelay: 500 },
    });
    await c.connect(endpoint);
    const s = await c.createSession();
    const ns = (await s.readNamespaceArray()).indexOf("urn:autoshovel:shovel-plc");
    await s.read({ nodeId: `ns=${ns};s=Shovel.Rtk.East`, attributeId: AttributeIds.Value });
    await s.close();
    await c.disconnect();
    made += 1;
  }
  fs.rmSync(scratch, { recursive: true, force: true });
  console.log(`visits ${made}`);
}

main().catch((e) => {
  console.error(e);
  process.exit(1);
});

"""A bystander nobody here wrote (python asyncua): anonymous sessions that
connect, read the pose and disconnect, again and again, until STOP_FILE
exists or N visits are made. Prints the number of visits made.

Usage: bystander.py ENDPOINT PKI_ROOT N STOP_FILE
"""

import asyncio
import os
import sys
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256


async def visit(endpoint, pki):
    c = Client(endpoint, timeout=10)
    c.application_uri = "urn:autoshovel:workstation"
    await c.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=str(pki / "workstation" / "own" / "cert.der"),
        private_key=str(pki / "workstation" / "private" / "private.pem"),
        server_certificate=str(pki / "plc" / "own" / "cert.der"),
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    async with c:
        ns = await c.get_namespace_index("urn:autoshovel:shovel-plc")
        await c.get_node(ua.NodeId("Shovel.Rtk.East", ns)).read_value()


async def main():
    endpoint, pki, n, stop = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
    made = 0
    while made < n and not os.path.exists(stop):
        await visit(endpoint, pki)
        made += 1
    print(made)


asyncio.run(main())

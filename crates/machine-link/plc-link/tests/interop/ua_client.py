"""An OPC UA client nobody here wrote (python asyncua) against plc-sim.

Usage: ua_client.py ENDPOINT PKI_ROOT PASSWORD
Connects with Basic256Sha256 SignAndEncrypt presenting the workstation's
certificate (pki/workstation), checks the server's against pki/plc, browses
the model, reads the RTK pose, writes a setpoint as the operator before and
after claiming control (OPC 10000-100 InitLock), tries an out-of-range
setpoint, a second operator session's claim and writes, and an anonymous
write, and prints what it saw as JSON.
"""

import asyncio
import json
import sys
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256

NS_URI = "urn:autoshovel:shovel-plc"


async def session(endpoint, pki, user=None, password=None):
    c = Client(endpoint, timeout=10)
    c.application_uri = "urn:autoshovel:workstation"
    await c.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=str(pki / "workstation" / "own" / "cert.der"),
        private_key=str(pki / "workstation" / "private" / "private.pem"),
        server_certificate=str(pki / "plc" / "own" / "cert.der"),
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    if user:
        c.set_user(user)
        c.set_password(password)
    return c


async def main():
    endpoint, pki, password = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    out = {}
    c = await session(endpoint, pki, "operator", password)
    async with c:
        ns = await c.get_namespace_index(NS_URI)
        out["namespace_index"] = ns
        shovel = await c.nodes.objects.get_child([f"{ns}:Shovel"])
        names = []
        for child in await shovel.get_children():
            names.append((await child.read_browse_name()).Name)
        out["shovel_children"] = sorted(names)
        rtk = await shovel.get_child([f"{ns}:Rtk"])
        rtk_names = sorted([(await n.read_browse_name()).Name for n in await rtk.get_children()])
        out["rtk_children"] = rtk_names

        def node(s):
            return c.get_node(ua.NodeId(s, ns))

        out["east_m"] = await node("Shovel.Rtk.East").read_value()
        out["north_m"] = await node("Shovel.Rtk.North").read_value()
        out["heading_deg"] = await node("Shovel.Rtk.Heading").read_value()
        out["quality"] = await node("Shovel.Rtk.FixQuality").read_value()
        ts = await node("Shovel.Rtk.Timestamp").read_value()
        out["timestamp"] = ts.isoformat() if ts else None
        out["max_rpm"] = await node("Shovel.Limits.MotorMaxSpeed").read_value()
        dt = await node("Shovel.Crawler.Left.SpeedSetpoint").read_data_type_as_variant_type()
        out["setpoint_type"] = dt.name
        try:
            await node("Shovel.Crawler.Left.SpeedSetpoint").write_value(ua.Variant(12.5, ua.VariantType.Double))
            out["write_unclaimed"] = "Good"
        except ua.UaStatusCodeError as e:
            out["write_unclaimed"] = type(e).__name__
        control = node("Shovel.Control")
        out["init_lock"] = await control.call_method(ua.NodeId("Shovel.Control.InitLock", ns), "asyncua interop")
        out["locking_user"] = await node("Shovel.Control.LockingUser").read_value()
        await node("Shovel.Crawler.Left.SpeedSetpoint").write_value(ua.Variant(123.5, ua.VariantType.Double))
        out["write_in_range"] = "Good"
        # A second operator session: its claim and its writes are refused.
        other = await session(endpoint, pki, "operator", password)
        async with other:
            o_control = other.get_node(ua.NodeId("Shovel.Control", ns))
            out["second_init_lock"] = await o_control.call_method(ua.NodeId("Shovel.Control.InitLock", ns), "second")
            try:
                await other.get_node(ua.NodeId("Shovel.Crawler.Left.SpeedSetpoint", ns)).write_value(
                    ua.Variant(-2000.0, ua.VariantType.Double)
                )
                out["second_write"] = "Good"
            except ua.UaStatusCodeError as e:
                out["second_write"] = type(e).__name__
        try:
            await node("Shovel.Crawler.Right.SpeedSetpoint").write_value(ua.Variant(1e9, ua.VariantType.Double))
            out["write_out_of_range"] = "Good"
        except ua.UaStatusCodeError as e:
            out["write_out_of_range"] = type(e).__name__
        await asyncio.sleep(0.2)  # the PLC publishes its state every millisecond
        out["fault_after"] = await node("Shovel.Fault.Active").read_value()
    c = await session(endpoint, pki)
    async with c:
        ns = await c.get_namespace_index(NS_URI)
        out["anonymous_read_east"] = await c.get_node(ua.NodeId("Shovel.Rtk.East", ns)).read_value()
        try:
            await c.get_node(ua.NodeId("Shovel.Crawler.Left.SpeedSetpoint", ns)).write_value(
                ua.Variant(10.0, ua.VariantType.Double)
            )
            out["anonymous_write"] = "Good"
        except ua.UaStatusCodeError as e:
            out["anonymous_write"] = type(e).__name__
    print(json.dumps(out))


asyncio.run(main())

"""The peer of `cargo run --release -p autoshovel-plc-link --example roundtrip`:
python asyncua (PyPI) as the workstation's client against the same plc-sim,
the same two calls (a Read of the 18 nodes the workstation reads, a Write of
both setpoints) over Basic256Sha256 SignAndEncrypt as the operator, holding
control (InitLock on Shovel.Control, a heartbeat every 50 ms) as `drive` does.

Usage: asyncua_roundtrip.py ENDPOINT PKI_ROOT PASSWORD [N]
(start `autoshovel plc-sim --manual --pki PKI_ROOT --port 4840` first).
"""

import asyncio
import statistics
import sys
import time
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256

NODES = [
    "Shovel.Clock", "Shovel.Rtk.East", "Shovel.Rtk.North", "Shovel.Rtk.Heading",
    "Shovel.Rtk.FixQuality", "Shovel.Rtk.Timestamp", "Shovel.Crawler.Left.Speed",
    "Shovel.Crawler.Right.Speed", "Shovel.Fault.Active", "Shovel.Fault.Text", "Shovel.Mode",
    "Shovel.Limits.MotorMaxSpeed", "Shovel.Limits.MotorMaxAcceleration",
    "Shovel.Crawler.Left.Frequency", "Shovel.Crawler.Left.Current", "Shovel.Crawler.Left.Voltage",
    "Shovel.Crawler.Right.Frequency", "Shovel.Crawler.Right.Current",
]


def q(xs, p):
    xs = sorted(xs)
    return xs[min(len(xs) - 1, round(p * (len(xs) - 1)))]


async def main():
    endpoint, pki, password = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    n = int(sys.argv[4]) if len(sys.argv) > 4 else 2000
    c = Client(endpoint, timeout=10)
    c.application_uri = "urn:autoshovel:workstation"
    await c.set_security(
        SecurityPolicyBasic256Sha256,
        certificate=str(pki / "workstation" / "own" / "cert.der"),
        private_key=str(pki / "workstation" / "private" / "private.pem"),
        server_certificate=str(pki / "plc" / "own" / "cert.der"),
        mode=ua.MessageSecurityMode.SignAndEncrypt,
    )
    c.set_user("operator")
    c.set_password(password)
    async with c:
        ns = await c.get_namespace_index("urn:autoshovel:shovel-plc")
        nodes = [c.get_node(ua.NodeId(s, ns)) for s in NODES]
        left = c.get_node(ua.NodeId("Shovel.Crawler.Left.SpeedSetpoint", ns))
        right = c.get_node(ua.NodeId("Shovel.Crawler.Right.SpeedSetpoint", ns))
        control = c.get_node(ua.NodeId("Shovel.Control", ns))
        [status] = [await control.call_method(ua.NodeId("Shovel.Control.InitLock", ns), "asyncua roundtrip")]
        assert status == 0, f"InitLock: {status} (another session holds control)"
        beat = c.get_node(ua.NodeId("Shovel.Workstation.Heartbeat", ns))

        async def heartbeat():
            k = 1
            while True:
                await beat.write_value(ua.Variant(k, ua.VariantType.UInt32))
                k += 1
                await asyncio.sleep(0.05)

        beating = asyncio.create_task(heartbeat())
        read, write = [], []
        for i in range(n):
            t = time.perf_counter()
            await c.read_values(nodes)
            read.append((time.perf_counter() - t) * 1e3)
            t = time.perf_counter()
            await c.write_values(
                [left, right],
                [ua.Variant(float(i % 100), ua.VariantType.Double), ua.Variant(0.0, ua.VariantType.Double)],
            )
            write.append((time.perf_counter() - t) * 1e3)
        beating.cancel()
        await control.call_method(ua.NodeId("Shovel.Control.ExitLock", ns))
    print(f"python asyncua client, {n} round trips each")
    print("| call | p50 [ms] | p99 [ms] | max [ms] |\n|---|---|---|---|")
    for name, xs in [("state read (18 nodes)", read), ("setpoint write (2 nodes)", write)]:
        print(f"| {name} | {q(xs, 0.5):.3f} | {q(xs, 0.99):.3f} | {max(xs):.3f} |")


asyncio.run(main())

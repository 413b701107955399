"""A shovel PLC nobody here wrote: a small python asyncua server on the
model of docs/machine-link.md, for `autoshovel drive` to run against.

Usage: ua_plc.py PORT PKI_ROOT PASSWORD X Y THETA [--wrong-type NODE] [--nan NODE]

Basic256Sha256 SignAndEncrypt only, the PLC's certificate from pki/plc, the
operator's user name and password required. An ideal crawler (no slip, no
noise; 1.5 m gauge, sprocket 0.3 m, gear 38, 3000 rpm, 6000 rpm/s) at 10 ms
steps, RTK fixes at 10 Hz with their own timestamps, a 250 ms heartbeat
watchdog that latches a fault and ends the lock, an instance id, and control
on OPC 10000-100's LockingServices (Shovel.Control): InitLock / ExitLock /
RenewLock / BreakLock, setpoints obeyed only while locked. asyncua's method
callbacks do not see the calling session, so this lock is the first
claimant's until released or lost, not bound to a session as plc-sim's is.
No Simulator folder: it is a PLC, not plc-sim.
`--wrong-type NODE` makes that node an Int32; `--nan NODE` makes it NaN.
It prints "ready" once listening and runs until killed.
"""

import asyncio
import datetime
import math
import sys
import time
from pathlib import Path

from asyncua import Server, ua
from asyncua.crypto.permission_rules import User, UserRole
from asyncua.server.user_managers import UserManager

NS_URI = "urn:autoshovel:shovel-plc"
GAUGE, R_S, GEAR, MAX_RPM, MAX_ACC = 1.5, 0.3, 38.0, 3000.0, 6000.0
K = 2 * math.pi * R_S / (60 * GEAR)  # m/s per rpm

VARS = [
    ("Shovel.Crawler.Left.SpeedSetpoint", ua.VariantType.Double, 0.0, True),
    ("Shovel.Crawler.Left.Speed", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Left.Frequency", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Left.Current", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Left.Voltage", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Right.SpeedSetpoint", ua.VariantType.Double, 0.0, True),
    ("Shovel.Crawler.Right.Speed", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Right.Frequency", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Right.Current", ua.VariantType.Double, 0.0, False),
    ("Shovel.Crawler.Right.Voltage", ua.VariantType.Double, 0.0, False),
    ("Shovel.Rtk.East", ua.VariantType.Double, 0.0, False),
    ("Shovel.Rtk.North", ua.VariantType.Double, 0.0, False),
    ("Shovel.Rtk.Heading", ua.VariantType.Double, 0.0, False),
    ("Shovel.Rtk.FixQuality", ua.VariantType.Byte, 0, False),
    ("Shovel.Rtk.Timestamp", ua.VariantType.DateTime, None, False),
    ("Shovel.Clock", ua.VariantType.DateTime, None, False),
    ("Shovel.Workstation.Heartbeat", ua.VariantType.UInt32, 0, True),
    ("Shovel.Mode", ua.VariantType.Byte, 1, False),
    ("Shovel.Fault.Active", ua.VariantType.Boolean, False, False),
    ("Shovel.Fault.Code", ua.VariantType.UInt32, 0, False),
    ("Shovel.Fault.Text", ua.VariantType.String, "", False),
    ("Shovel.Limits.MotorMaxSpeed", ua.VariantType.Double, MAX_RPM, False),
    ("Shovel.Limits.MotorMaxAcceleration", ua.VariantType.Double, MAX_ACC, False),
    ("Shovel.InstanceId", ua.VariantType.String, f"python-{time.time_ns()}", False),
    ("Shovel.Control.Locked", ua.VariantType.Boolean, False, False),
    ("Shovel.Control.LockingClient", ua.VariantType.String, "", False),
    ("Shovel.Control.LockingUser", ua.VariantType.String, "", False),
    ("Shovel.Control.RemainingLockTime", ua.VariantType.Double, 0.0, False),
]


class Operator(UserManager):
    def __init__(self, password):
        self.password = password

    def get_user(self, iserver, username=None, password=None, certificate=None):
        if username == "operator" and password == self.password:
            return User(role=UserRole.User, name=username)
        return None


async def main():
    port, pki, password = int(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
    wrong = sys.argv[sys.argv.index("--wrong-type") + 1] if "--wrong-type" in sys.argv else None
    nan = sys.argv[sys.argv.index("--nan") + 1] if "--nan" in sys.argv else None
    server = Server(user_manager=Operator(password))
    await server.init()
    server.set_endpoint(f"opc.tcp://127.0.0.1:{port}/")
    server.set_server_name("python asyncua shovel PLC")
    await server.set_application_uri("urn:autoshovel:plc-sim")
    server.set_security_policy([ua.SecurityPolicyType.Basic256Sha256_SignAndEncrypt])
    server.set_identity_tokens([ua.UserNameIdentityToken])
    await server.load_certificate(str(pki / "plc" / "own" / "cert.der"))
    await server.load_private_key(str(pki / "plc" / "private" / "private.pem"))
    ns = await server.register_namespace(NS_URI)

    folders = {}

    async def folder(path):
        if path in folders:
            return folders[path]
        parent_path, _, leaf = path.rpartition(".")
        parent = await folder(parent_path) if parent_path else server.nodes.objects
        f = await parent.add_folder(ua.NodeId(path, ns), ua.QualifiedName(leaf, ns))
        folders[path] = f
        return f

    nodes = {}
    for path, vt, init, writable in VARS:
        parent = await folder(path.rpartition(".")[0])
        leaf = path.rpartition(".")[2]
        if path == wrong:
            vt, init = ua.VariantType.Int32, 0
        if vt == ua.VariantType.DateTime:
            init = datetime.datetime(1601, 1, 1, tzinfo=datetime.timezone.utc)
        kind = {"Shovel.Control.RemainingLockTime": ua.NodeId(ua.ObjectIds.Duration)}.get(path)
        v = await parent.add_variable(
            ua.NodeId(path, ns), ua.QualifiedName(leaf, ns), ua.Variant(init, vt), datatype=kind
        )
        if writable:
            await v.set_writable()
        nodes[path] = (v, vt)

    lock = {"held": False}

    def lock_method(name):
        def call(parent, *args):
            if name == "InitLock":
                if lock["held"]:
                    return [ua.Variant(-1, ua.VariantType.Int32)]
                lock["held"] = True
            elif not lock["held"]:
                return [ua.Variant(-1, ua.VariantType.Int32)]
            elif name != "RenewLock":
                lock["held"] = False
            return [ua.Variant(0, ua.VariantType.Int32)]

        return call

    control = await folder("Shovel.Control")
    for name in ["InitLock", "RenewLock", "ExitLock", "BreakLock"]:
        inargs = [ua.VariantType.String] if name == "InitLock" else []
        await control.add_method(
            ua.NodeId(f"Shovel.Control.{name}", ns), ua.QualifiedName(name, ns),
            lock_method(name), inargs, [ua.VariantType.Int32],
        )

    async def put(path, value):
        v, vt = nodes[path]
        if path == nan:
            value = float("nan")
        if vt == ua.VariantType.Int32:
            value = int(value) if not isinstance(value, datetime.datetime) else 0
        await v.write_value(ua.Variant(value, vt))

    # The machine at rest at the given pose (θ from east, counter-clockwise).
    x, y, th = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
    nl = nr = 0.0
    hb, hb_at, fault = None, None, None
    t0 = time.monotonic()
    next_fix = 0.0
    dt = 0.01

    async with server:
        print("ready", flush=True)
        last = time.monotonic()
        while True:
            await asyncio.sleep(dt)
            now = time.monotonic()
            step = now - last
            last = now
            beat = await nodes["Shovel.Workstation.Heartbeat"][0].read_value()
            if beat != hb:
                hb, hb_at = beat, now
            if fault is None and hb_at is not None and now - hb_at > 0.25:
                lock["held"] = False
                fault = "heartbeat lost"
                await put("Shovel.Fault.Active", True)
                await put("Shovel.Fault.Code", 1)
                await put("Shovel.Fault.Text", fault)
            await put("Shovel.Control.Locked", lock["held"])
            await put("Shovel.Control.LockingUser", "operator" if lock["held"] else "")
            if fault is None and hb_at is not None and lock["held"]:
                want_l = await nodes["Shovel.Crawler.Left.SpeedSetpoint"][0].read_value()
                want_r = await nodes["Shovel.Crawler.Right.SpeedSetpoint"][0].read_value()
            else:
                want_l = want_r = 0.0
            dn = MAX_ACC * step
            nl += max(-dn, min(dn, max(-MAX_RPM, min(MAX_RPM, want_l)) - nl))
            nr += max(-dn, min(dn, max(-MAX_RPM, min(MAX_RPM, want_r)) - nr))
            vl, vr = nl * K, nr * K
            v, w = (vl + vr) / 2, (vr - vl) / GAUGE
            x += v * step * math.cos(th + w * step / 2)
            y += v * step * math.sin(th + w * step / 2)
            th += w * step
            t = now - t0
            stamp = datetime.datetime.now(datetime.timezone.utc)
            await put("Shovel.Clock", stamp)
            await put("Shovel.Crawler.Left.Speed", nl)
            await put("Shovel.Crawler.Right.Speed", nr)
            if t >= next_fix:
                next_fix += 0.1
                heading = math.degrees(math.pi / 2 - th) % 360.0
                await put("Shovel.Rtk.East", x)
                await put("Shovel.Rtk.North", y)
                await put("Shovel.Rtk.Heading", heading)
                await put("Shovel.Rtk.FixQuality", 4)
                await put("Shovel.Rtk.Timestamp", stamp)


asyncio.run(main())

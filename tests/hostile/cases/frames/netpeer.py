# SPDX-License-Identifier: MIT
"""Helpers of the hostile-input suite's network cases (frames/ and http/): start
`llsf-comm-hub` or `llsfsim serve` on free ports, talk to them with raw sockets, and check that
they survive, refuse and stay small. A check that fails prints `FAIL: ...` and exits 1; a case
that passes prints its findings and exits 0.
"""
import json
import os
import re
import signal
import socket
import struct
import subprocess
import sys
import time

TMP = os.environ.get("CASE_TMP", ".")
LOOPBACK = "127.0.0.1"


def fail(message):
    print(f"FAIL: {message}")
    sys.stdout.flush()
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)


def lock_frame(n=1, comp=2100, msg_type=1, payload=None):
    """A 2013 frame of an agent LockMessage (GET, agent R1, resource M<n>)."""
    if payload is None:
        agent, resource = b"R1", b"M" + str(n).encode()
        payload = (b"\x08\x01" + b"\x12" + bytes([len(agent)]) + agent + b"\x1a" +
                   bytes([len(resource)]) + resource)
    return struct.pack(">HHI", comp, msg_type, len(payload)) + payload


def header(comp, msg_type, size):
    return struct.pack(">HHI", comp, msg_type, size)


class Proc:
    """A server process whose stdout is read until `ready` (a regex) has matched."""

    def __init__(self, args, ready, timeout=5.0, prefix=None):
        self.err_path = os.path.join(TMP, f"server-{os.getpid()}-{time.monotonic_ns()}.err")
        self.err_file = open(self.err_path, "wb")
        self.p = subprocess.Popen((prefix or []) + args, stdout=subprocess.PIPE,
                                  stderr=self.err_file, cwd=TMP)
        self.lines = []
        deadline = time.monotonic() + timeout
        pattern = re.compile(ready)
        while time.monotonic() < deadline:
            line = self.p.stdout.readline().decode("utf-8", "replace")
            if not line:
                fail(f"{args[0]} ended before it was ready: {self.stderr()}")
            self.lines.append(line.rstrip("\n"))
            if pattern.search(line):
                return
        fail(f"{args[0]} not ready within {timeout} s")

    def alive(self):
        return self.p.poll() is None

    def status(self, key):
        """A /proc/PID/status field in kB (VmRSS, VmHWM)."""
        with open(f"/proc/{self.p.pid}/status") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1])
        return 0

    def cpu_seconds(self):
        with open(f"/proc/{self.p.pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def open_fds(self):
        return len(os.listdir(f"/proc/{self.p.pid}/fd"))

    def stderr(self):
        if not self.err_file.closed:
            self.err_file.flush()
        with open(self.err_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def stop(self):
        """SIGTERM; returns (exit code, rest of stdout, stderr)."""
        if self.alive():
            self.p.send_signal(signal.SIGTERM)
        try:
            out, _ = self.p.communicate(timeout=5)
        except subprocess.TimeoutExpired:
            self.p.kill()
            out, _ = self.p.communicate()
        self.err_file.close()
        return self.p.returncode, out.decode("utf-8", "replace"), self.stderr()


class Hub(Proc):
    """llsf-comm-hub with peers robot1 and refbox (ports chosen and learnt) and the stream
    server on a free port. `hub_yaml`: the hub config's text, if any."""

    def __init__(self, extra=(), hub_yaml=None, peers=None, prefix=None):
        sockets = os.path.join(TMP, "sockets.yaml")
        with open(sockets, "w") as f:
            f.write("udp_peers:\n" + (peers or "  - {name: robot1}\n  - {name: refbox, channel: \"*\"}\n"))
        args = [os.environ["LLSF_COMM_HUB"], "--sockets", sockets, "--stream-port", "0"]
        if hub_yaml is not None:
            config = os.path.join(TMP, "hub.yaml")
            with open(config, "w") as f:
                f.write(hub_yaml)
            args += ["--config", config]
        super().__init__(args + list(extra), r"stream server listens on", prefix=prefix)
        self.ports = {}
        for line in self.lines:
            m = re.match(r"peer (\S+)\s.*listens on [\d.]+:(\d+)", line)
            if m:
                self.ports[m.group(1)] = int(m.group(2))
            m = re.match(r"stream server listens on [\d.]+:(\d+)", line)
            if m:
                self.stream_port = int(m.group(1))

    def finish(self):
        """Stops the hub; returns (counters JSON, the stream summary line, stderr)."""
        code, out, err = self.stop()
        check(code == 0, f"llsf-comm-hub exited {code}: {err[-500:]}")
        counters = None
        summary = ""
        for line in out.splitlines():
            if line.startswith("{"):
                counters = json.loads(line)
            if line.startswith("stream server:"):
                summary = line
        check(counters is not None, "no counters printed at the end")
        return counters, summary, err


def udp_socket():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind((LOOPBACK, 0))
    s.settimeout(0.05)
    return s


def udp_receive_all(s, wait=0.3):
    """Datagrams arriving on `s` within `wait` seconds."""
    got = []
    deadline = time.monotonic() + wait
    while time.monotonic() < deadline:
        try:
            got.append(s.recv(65536))
        except socket.timeout:
            pass
    return got


def tcp_connect(port, timeout=2.0):
    s = socket.create_connection((LOOPBACK, port), timeout=timeout)
    return s


def closed_by_peer(s, wait):
    """True if the other side closes `s` (EOF or reset) within `wait` seconds."""
    s.settimeout(0.05)
    deadline = time.monotonic() + wait
    while time.monotonic() < deadline:
        try:
            if s.recv(65536) == b"":
                return True
        except socket.timeout:
            continue
        except OSError:
            return True
    return False


def stream_roundtrip_ok(hub, n=3):
    """A fresh stream client's `n` valid frames are received (counted at the end)."""
    s = tcp_connect(hub.stream_port)
    s.sendall(b"".join(lock_frame(i) for i in range(n)))
    time.sleep(0.2)
    s.close()


class Serve(Proc):
    """`llsfsim serve` on a free port with a small viewer folder (index.html, viewer.js) and a
    recordings folder in the case's temporary folder."""

    def __init__(self, extra=(), prefix=None):
        self.viewer = os.path.join(TMP, "dist")
        self.recordings = os.path.join(TMP, "recordings")
        os.makedirs(self.viewer, exist_ok=True)
        os.makedirs(self.recordings, exist_ok=True)
        with open(os.path.join(self.viewer, "index.html"), "w") as f:
            f.write("<!doctype html><title>viewer</title>")
        with open(os.path.join(self.viewer, "viewer.js"), "w") as f:
            f.write("console.log(1);")
        args = [os.environ["LLSFSIM"], "serve", "--port", "0", "--db",
                os.path.join(TMP, "none.db"), "--viewer", self.viewer, "--recordings",
                self.recordings] + list(extra)
        super().__init__(args, r"llsfsim serve: http://", prefix=prefix)
        self.port = int(re.search(r":(\d+)/", self.lines[-1]).group(1))


def http_get(port, target, headers=(), timeout=3.0):
    """(status, body) of one GET on a fresh connection; the target is sent as given."""
    s = tcp_connect(port, timeout)
    request = f"GET {target} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n"
    for h in headers:
        request += h + "\r\n"
    s.sendall((request + "\r\n").encode("latin-1"))
    data = b""
    s.settimeout(timeout)
    try:
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            data += chunk
    except (socket.timeout, ConnectionResetError):
        pass
    s.close()
    m = re.match(rb"HTTP/1\.1 (\d+)", data)
    check(m is not None, f"GET {target[:60]}: no HTTP answer ({data[:80]!r})")
    return int(m.group(1)), data.split(b"\r\n\r\n", 1)[-1].decode("utf-8", "replace")


def raw_exchange(port, data, timeout=3.0):
    """Sends raw bytes, returns what comes back until the server closes or `timeout`."""
    s = tcp_connect(port, timeout)
    try:
        s.sendall(data)
    except OSError:
        pass
    out = b""
    s.settimeout(timeout)
    try:
        while True:
            chunk = s.recv(65536)
            if not chunk:
                break
            out += chunk
    except (socket.timeout, OSError):
        pass
    s.close()
    return out


def websocket_upgrade(port, target="/api/live"):
    """Opens a WebSocket handshake; returns (socket, status)."""
    s = tcp_connect(port)
    s.sendall((f"GET {target} HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
              .encode())
    s.settimeout(3.0)
    data = b""
    while b"\r\n\r\n" not in data:
        chunk = s.recv(4096)
        if not chunk:
            break
        data += chunk
    m = re.match(rb"HTTP/1\.1 (\d+)", data)
    return s, int(m.group(1)) if m else 0

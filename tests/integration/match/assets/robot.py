"""Test robot controller: one behaviour per command-line word (runs inside a test container)."""

import json
import os
import signal
import socket
import sys
import threading
import time

LOGS = "/robocup-logs"


def log(name, data):
    with open(os.path.join(LOGS, name), "w") as handle:
        json.dump(data, handle)


def sim_addr():
    host, port = os.environ["ROBOCUP_SIMULATOR_ADDR"].rsplit(":", 1)
    return host, int(port)


def try_connect(host, port, timeout=1.0):
    sock = socket.socket()
    sock.settimeout(timeout)
    try:
        sock.connect((host, port))
        return "connected"
    except OSError as exc:
        return f"failed: {exc}"
    finally:
        sock.close()


def try_simulator(retry_s=20.0):
    """The simulator starts side by side with the robots: retry while it does not listen yet,
    as the robot clients do."""
    deadline = time.monotonic() + retry_s
    while True:
        result = try_connect(*sim_addr())
        if result == "connected" or time.monotonic() > deadline:
            return result
        time.sleep(0.2)


def connect_simulator(retry_s=20.0):
    deadline = time.monotonic() + retry_s
    while True:
        try:
            return socket.create_connection(sim_addr(), timeout=10)
        except ConnectionRefusedError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def measure(sock):
    """Receive until EOF; the rate in bit/s after the first 0.5 s (token bucket burst)."""
    marks = []
    total = 0
    while True:
        data = sock.recv(262144)
        if not data:
            break
        total += len(data)
        marks.append((time.monotonic(), total))
    if len(marks) < 2 or marks[-1][0] - marks[0][0] < 1.0:
        return None
    start = next(m for m in marks if m[0] >= marks[0][0] + 0.5)
    return (total - start[1]) * 8 / (marks[-1][0] - start[0])


def wait_forever():
    while True:
        time.sleep(1)


def main(argv):
    mode = argv[1] if len(argv) > 1 else "env"
    print(f"robot {os.environ.get('ROBOCUP_TEAM_COLOR')}-{os.environ.get('ROBOCUP_ROBOT_ID')} "
          f"mode {mode}", flush=True)
    if mode == "env":
        env = {k: v for k, v in os.environ.items() if k.startswith("ROBOCUP_")}
        mounts = sorted({line.split()[4] for line in open("/proc/self/mountinfo")})
        status = dict(line.split(":", 1) for line in open("/proc/self/status") if ":" in line)
        log("env.json", {"env": env, "hostname": socket.gethostname(), "uid": os.getuid(),
                         "mounts": mounts, "cap_eff": status["CapEff"].strip(),
                         "no_new_privs": status.get("NoNewPrivs", "").strip()})
        reach = {}
        for target in argv[2:]:
            host, port = target.rsplit(":", 1)
            reach[target] = try_connect(host, int(port))
        reach["simulator"] = try_simulator()
        log("reach.json", reach)
        print("env written", flush=True)
        wait_forever()
    if mode == "listen":
        server = socket.socket()
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        server.bind(("0.0.0.0", 5000))
        server.listen(8)
        while True:
            conn, _ = server.accept()
            conn.close()
    if mode == "probe":
        path = os.path.join(LOGS, "targets.json")
        deadline = time.monotonic() + 30
        while not os.path.exists(path) and time.monotonic() < deadline:
            time.sleep(0.1)
        time.sleep(0.2)
        targets = json.load(open(path))
        reach = {}

        def probe(name, host, port):
            """The simulator and teammates start side by side with this robot: until they are
            up, a connection is refused, or times out while their address is not on the network
            yet. Retry any failure for a while; a target that is walled off fails every time."""
            until = time.monotonic() + 5
            reach[name] = try_connect(host, port)
            while reach[name] != "connected" and time.monotonic() < until:
                time.sleep(0.2)
                reach[name] = try_connect(host, port)

        probes = [threading.Thread(target=probe, args=(name, host, port))
                  for name, (host, port) in targets.items()]
        for thread in probes:
            thread.start()
        for thread in probes:
            thread.join()
        log("reach.json", reach)
        print("probe done", flush=True)
        wait_forever()
    if mode == "sigterm":
        def on_term(signum, frame):
            with open(os.path.join(LOGS, "term.txt"), "w") as handle:
                handle.write("got SIGTERM\n")
            time.sleep(1.0)
            with open(os.path.join(LOGS, "term.txt"), "a") as handle:
                handle.write("flushed\n")
            sys.exit(0)
        signal.signal(signal.SIGTERM, on_term)
        open(os.path.join(LOGS, "ready.txt"), "w").close()
        wait_forever()
    if mode == "oom":
        hog = []
        while True:
            hog.append(bytearray(8 * 1024 * 1024))
            time.sleep(0.01)
    if mode == "fill":
        written = 0
        error = ""
        try:
            with open(os.path.join(LOGS, "big.bin"), "wb") as handle:
                chunk = b"x" * (1024 * 1024)
                while written < 200 * 1024 * 1024:
                    handle.write(chunk)
                    handle.flush()
                    written += len(chunk)
        except OSError as exc:
            error = str(exc)
        print(json.dumps({"written": written, "error": error}), flush=True)
        wait_forever()
    if mode == "send":
        seconds = float(argv[2]) if len(argv) > 2 else 3.0
        sock = connect_simulator()
        chunk = b"\0" * 65536
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            sock.sendall(chunk)
        sock.close()
        print("sent", flush=True)
        wait_forever()
    if mode == "recv":  # ask the simulator for data, measure the rate that arrives
        seconds = float(argv[2]) if len(argv) > 2 else 3.0
        sock = connect_simulator()
        sock.sendall(f"DOWNLOAD {seconds}\n".encode())
        log("recv.json", {"rate_bit_s": measure(sock)})
        wait_forever()
    if mode == "sink":  # teammates send here (port 5001)
        server = socket.socket()
        server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        server.bind(("0.0.0.0", 5001))
        server.listen(1)
        conn, _ = server.accept()
        log("sink.json", {"rate_bit_s": measure(conn)})
        wait_forever()
    if mode == "sendmate":
        seconds = float(argv[2]) if len(argv) > 2 else 3.0
        target = os.environ["ROBOCUP_TEAM_PLAYER1_IP"]
        deadline = time.monotonic() + 20
        while True:
            try:
                sock = socket.create_connection((target, 5001), timeout=2)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.1)
        chunk = b"\0" * 16384
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            sock.sendall(chunk)
        sock.close()
        wait_forever()
    if mode == "exit":
        sys.exit(3)
    raise SystemExit(f"unknown mode {mode}")


if __name__ == "__main__":
    main(sys.argv)

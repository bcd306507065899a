"""Test stand-in for the simulator process: accepts robot connections on the player ports,
counts what arrives, runs for a given wall time, writes the files of the shared contract."""

import json
import os
import socket
import sys
import threading
import time

spec = json.load(open("/match/match_spec.json"))
duration = float(sys.argv[1]) if len(sys.argv) > 1 else 3.0
exit_code = int(sys.argv[2]) if len(sys.argv) > 2 else 0
out = "/match/out"
os.makedirs(out, exist_ok=True)
stats = {}
lock = threading.Lock()


def serve(key, port):
    server = socket.socket()
    server.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    server.bind(("0.0.0.0", port))
    server.listen(4)
    while True:
        conn, peer = server.accept()
        threading.Thread(target=count, args=(key, conn, peer), daemon=True).start()


def count(key, conn, peer):
    head = conn.recv(64, socket.MSG_PEEK)
    if head.startswith(b"DOWNLOAD"):
        seconds = float(conn.recv(64).split()[1])
        chunk = b"\0" * 65536
        end = time.monotonic() + seconds
        sent = 0
        while time.monotonic() < end:
            conn.sendall(chunk)
            sent += len(chunk)
        conn.close()
        with lock:
            stats[key] = {"peer": peer[0], "bytes": 0, "sent": sent, "rate_bit_s": None}
        return
    total = 0
    first = last = None
    marks = []
    while True:
        data = conn.recv(262144)
        if not data:
            break
        now = time.monotonic()
        first = first or now
        last = now
        total += len(data)
        marks.append((now, total))
    rate = None
    windows = []
    if first is not None and last - first > 1.0:
        # steady state: skip the first 0.5 s (token bucket burst)
        start = next((m for m in marks if m[0] >= first + 0.5), marks[0])
        rate = (total - start[1]) * 8 / (last - start[0])
        # the rate in each whole second after that: a starved sender (a loaded machine) lowers
        # some of them, a shaper that lets too much through raises every one
        begin = start
        for mark in marks:
            if mark[0] - begin[0] >= 1.0:
                windows.append((mark[1] - begin[1]) * 8 / (mark[0] - begin[0]))
                begin = mark
    with lock:
        stats[key] = {"peer": peer[0], "bytes": total, "rate_bit_s": rate,
                      "window_rates_bit_s": windows}


for color in ("red", "blue"):
    for player in spec[color]["players"]:
        key = f"{color}-{player['number']}"
        threading.Thread(target=serve, args=(key, player["port"]), daemon=True).start()
        with lock:
            stats.setdefault(key, {"peer": None, "bytes": 0, "rate_bit_s": None})
print("fake simulator up", flush=True)
time.sleep(duration)
with lock:
    robots = dict(stats)
result = {
    "match_id": spec["match_id"], "seed": spec["seed"], "state": "FINISHED",
    "score": {"red": 1, "blue": 0}, "winner": "red", "sim_time_ms": int(duration * 1000),
    "real_time_s": duration, "real_time_factor": 1.0, "events_summary": {"GOAL": 1},
    "robots": robots, "versions": {"fakesim": "1"},
}
for name in ("replay.hlvsrec", "referee.log", "referee_events.jsonl", "gamecontroller.log"):
    open(os.path.join(out, name), "w").write("test\n")
json.dump(result, open(os.path.join(out, "sim_result.json"), "w"))
print("fake simulator done", file=sys.stderr, flush=True)
sys.exit(exit_code)

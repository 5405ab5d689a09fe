"""A hostile client of `l6470emu serve`: connects to its socket directly (no preload) and sends
garbage for a while: random bytes, truncated headers, protocol-shaped requests with bogus ops,
handles, sizes and payloads, oversized packets; reconnects often. Never sends a control
request (that is the operator's channel, and the soak's recording must survive).
Usage: garbage_client.py SOCKET SEED SECONDS. Prints how many packets it sent."""
import os
import random
import socket
import struct
import sys
import time

path, seed, seconds = sys.argv[1], int(sys.argv[2]), float(sys.argv[3])
rng = random.Random(seed)
end = time.monotonic() + seconds
sent = 0
while time.monotonic() < end:
    try:
        s = socket.socket(socket.AF_UNIX, socket.SOCK_SEQPACKET)
        s.settimeout(0.2)
        s.connect(path)
        for _ in range(rng.randint(1, 30)):
            r = rng.random()
            if r < 0.25:
                pkt = os.urandom(rng.randint(0, 40))  # random bytes, often shorter than a header
            elif r < 0.5:
                op = rng.choice([0, 1, 2, 3, 4, 5, 6, 7, 9, 0xFFFFFFFF, rng.getrandbits(32)])
                payload = os.urandom(rng.randint(0, 600))
                declared = rng.choice([len(payload), rng.getrandbits(32), 0])
                pkt = struct.pack("<IIQQ", op, declared, rng.getrandbits(64), rng.getrandbits(64)) + payload
            elif r < 0.75:
                n = rng.choice([0, 1, 2, 511, 4096, 100000, rng.getrandbits(64)])  # transfer counts
                body = os.urandom(32 * rng.randint(0, 8) + rng.randint(0, 31))
                pkt = struct.pack("<IIQQ", 5, len(body), rng.getrandbits(64), n) + body
            elif r < 0.9:
                pkt = struct.pack("<IIQQ", rng.choice([4, 6, 7]), 0, rng.getrandbits(64), rng.getrandbits(64))
            else:
                pkt = os.urandom(rng.choice([70000, 300000]))  # large
            try:
                s.send(pkt)
                sent += 1
                if rng.random() < 0.5:
                    s.recv(1 << 16)
            except (socket.timeout, OSError):
                break
        s.close()
    except OSError:
        time.sleep(0.01)
print(f"sent={sent}")

"""The design server under load: N concurrent predictions and N stalled uploads against a real `matcad serve`.

Starts `python -m matcad serve --port 0` as its own process (whatever matcad PYTHONPATH names), then, with the
paper template's spec (a silicone wall: ~0.1-0.3 s per prediction)

  concurrent  N clients post a prediction at once: how many got 200, 503, other statuses, a reset or no answer;
              their times (median, max); the server's threads (peak, from /proc)
  stalled     N clients send headers and 10 bytes of a 1000-byte body, then stall: the server's threads while they
              stall, what a normal prediction gets meanwhile (status, time), how long until the stalled ones are
              dropped and the threads are back, and what the stalled clients finally read

Run: PYTHONPATH=. .venv/bin/python benchmarks/serve.py [N]   (default 50; counts, times in s)
"""

from __future__ import annotations

import json
import os
import socket
import statistics
import subprocess
import sys
import threading
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def threads(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("Threads:"):
            return int(line.split()[1])
    return -1


def start_server() -> tuple[subprocess.Popen, int]:
    """`matcad serve --port 0` from the matcad that PYTHONPATH names (made absolute; run outside any checkout so
    that the working folder does not decide which matcad runs)."""
    import tempfile

    path = os.pathsep.join(os.path.abspath(p) for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p)
    proc = subprocess.Popen([sys.executable, "-m", "matcad", "serve", "--port", "0"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=tempfile.gettempdir(),
                            env={**os.environ, "PYTHONPATH": path})
    line = proc.stdout.readline()
    port = int(line.split("http://127.0.0.1:")[1].split("/")[0])
    return proc, port


def request(port: int, body: bytes, timeout: float = 120.0) -> tuple[str, float]:
    """One POST /predict over a raw socket: ('200' | '503' | status | 'reset' | 'timeout' | 'refused', seconds)."""
    t0 = time.perf_counter()
    head = (f"POST /predict HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
            f"Content-Length: {len(body)}\r\nConnection: close\r\n\r\n").encode()
    try:
        with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
            s.sendall(head + body)
            data = b""
            while chunk := s.recv(65536):
                data += chunk
        status = data.split(b" ", 2)[1].decode() if data.startswith(b"HTTP/") else "empty"
    except ConnectionResetError:
        status = "reset"
    except ConnectionRefusedError:
        status = "refused"
    except (TimeoutError, socket.timeout):
        status = "timeout"
    except OSError as exc:
        status = type(exc).__name__
    return status, time.perf_counter() - t0


def concurrent(port: int, pid: int, n: int, body: bytes) -> None:
    results: list[tuple[str, float]] = []
    peak = [threads(pid)]
    done = threading.Event()

    def watch():
        while not done.is_set():
            peak.append(threads(pid))
            time.sleep(0.05)

    def one():
        results.append(request(port, body))

    watcher = threading.Thread(target=watch)
    watcher.start()
    clients = [threading.Thread(target=one) for _ in range(n)]
    t0 = time.perf_counter()
    for c in clients:
        c.start()
    for c in clients:
        c.join()
    done.set()
    watcher.join()
    counts = {k: sum(1 for s, _ in results if s == k) for k in sorted({s for s, _ in results})}
    times = [t for _, t in results]
    print(f"concurrent  {n} predictions: {counts}; time median {statistics.median(times):.2f} s, max "
          f"{max(times):.2f} s, all done in {time.perf_counter() - t0:.2f} s; server threads peak {max(peak)}")


def stalled(port: int, pid: int, n: int, body: bytes) -> None:
    base = threads(pid)
    socks = []
    head = (f"POST /predict HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Type: application/json\r\n"
            "Content-Length: 1000\r\n\r\n").encode()
    for _ in range(n):
        try:
            s = socket.create_connection(("127.0.0.1", port), timeout=5)
            s.sendall(head + b'{"spec": {')
            socks.append(s)
        except OSError:
            pass
    time.sleep(1.0)
    held = threads(pid)
    status, seconds = request(port, body, timeout=60)
    t0 = time.perf_counter()
    while threads(pid) > base + 1 and time.perf_counter() - t0 < 120:
        time.sleep(0.2)
    freed = time.perf_counter() - t0 + 1.0
    answers: dict[str, int] = {}
    for s in socks:
        try:
            s.settimeout(5)
            data = s.recv(65536)
            key = data.split(b" ", 2)[1].decode() if data.startswith(b"HTTP/") else ("closed" if not data else "?")
        except ConnectionResetError:
            key = "reset"
        except OSError as exc:
            key = type(exc).__name__
        answers[key] = answers.get(key, 0) + 1
        s.close()
    after_status, after_s = request(port, body)
    print(f"stalled     {len(socks)} of {n} uploads stalled: server threads {base} before, {held} while stalled, "
          f"back to {threads(pid)} after {freed:.1f} s; a prediction meanwhile: {status} in {seconds:.2f} s; "
          f"afterwards: {after_status} in {after_s:.2f} s; the stalled clients read {answers}")


def main(n: int) -> None:
    spec = tomllib.loads((ROOT / "templates" / "mat-paper.toml").read_text(encoding="utf-8"))
    body = json.dumps({"spec": spec}).encode()
    proc, port = start_server()
    try:
        request(port, body)  # warm up: the first prediction imports numpy and scipy
        concurrent(port, proc.pid, n, body)
        stalled(port, proc.pid, n, body)
    finally:
        proc.terminate()
        _, err = proc.communicate(timeout=30)
    print(f"server exit {proc.returncode}; stderr: {err.strip()[-300:] or '(empty)'}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 50)

#!/usr/bin/env python3
"""A frame's wait while `insitu-view serve` makes a large payload (issue 42: payloads under the
archive's lock). Each round asks a frame alone, then the same kind of frame 50 ms after a cold
light-field payload was asked (a camera subset not asked before, so none is cached), and prints
both waits and the payload's; at the end best, median and spread, with the CPU and load.

    python3 bench/bench_payload_concurrency.py INSITU_VIEW LIGHT_FIELD_ARCHIVE [ROUNDS]
"""
import json
import os
import statistics
import subprocess
import sys
import threading
import time
import urllib.request


def cpu_model():
    with open("/proc/cpuinfo") as info:
        for line in info:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown CPU"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    view, archive = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 5
    port = 8791
    server = subprocess.Popen([view, "serve", archive, "--port", str(port)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    base = f"http://127.0.0.1:{port}"
    try:
        for _ in range(100):
            try:
                listing = json.load(urllib.request.urlopen(base + "/api/archive"))
                break
            except OSError:
                time.sleep(0.1)
        else:
            sys.exit("the server did not answer")
        first = listing["steps"][0]
        step = first["step"] if isinstance(first, dict) else first

        def timed(path, headers=None):
            start = time.perf_counter()
            request = urllib.request.Request(base + path, headers=headers or {})
            body = urllib.request.urlopen(request).read()
            return time.perf_counter() - start, len(body)

        alone, during, payloads = [], [], []
        for i in range(rounds):
            alone.append(timed(f"/api/frame?step={step}&view=0&azimuth={10 + i}&session=a")[0])
            made = {}
            # Cameras within 100..(100 + 5 rounds) degrees of a direction no round repeats.
            lf = (f"/api/lightfield?step={step}&view=0&toward=1,{0.1 * i:.1f},1"
                  f"&within={100 + 5 * i}")

            def payload():
                made["lf"] = timed(lf, {"Accept-Encoding": "gzip"})

            thread = threading.Thread(target=payload)
            thread.start()
            time.sleep(0.05)
            during.append(timed(f"/api/frame?step={step}&view=0&azimuth={40 + i}&session=b")[0])
            thread.join()
            payloads.append(made["lf"][0])
            print(f"round {i}: frame alone {alone[-1] * 1e3:.0f} ms; frame asked during a cold "
                  f"light-field payload {during[-1] * 1e3:.0f} ms (the payload "
                  f"{payloads[-1] * 1e3:.0f} ms, {made['lf'][1] / 1e6:.1f} MB gzip)")
    finally:
        server.terminate()
        server.wait()

    def summary(name, values):
        ms = [v * 1e3 for v in values]
        print(f"{name}: best {min(ms):.0f} ms, median {statistics.median(ms):.0f} ms, "
              f"spread {min(ms):.0f}-{max(ms):.0f} ms")

    print(f"{cpu_model()}, {os.cpu_count()} threads, load average {os.getloadavg()[0]:.1f}, "
          f"{rounds} rounds")
    summary("frame alone", alone)
    summary("frame during a payload", during)
    summary("payload", payloads)


if __name__ == "__main__":
    main()

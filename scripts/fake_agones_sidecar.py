#!/usr/bin/env python3
"""A stand-in for the Agones SDK sidecar's REST API, for measuring `detsim serve --agones` here.

Listens on 127.0.0.1 at each of PORTS (one sidecar per game server, as in a pod) and answers every
SDK call the way the sidecar does (200 and `{}`; GET /gameserver a minimal GameServer). Each call
is logged as one JSON line to --log: {"port", "t" (seconds since the start), "method", "path",
"body"}. Stops on SIGTERM or SIGINT.

    fake_agones_sidecar.py --log calls.jsonl 9400 9401 ...
"""
import argparse
import json
import signal
import sys
import threading
import time
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

START = time.monotonic()
LOCK = threading.Lock()


def make_handler(port, log):
    class Handler(BaseHTTPRequestHandler):
        protocol_version = "HTTP/1.1"

        def _answer(self, body=b"{}"):
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def _record(self):
            length = int(self.headers.get("Content-Length") or 0)
            body = self.rfile.read(length).decode("utf-8", "replace") if length else ""
            line = json.dumps({"port": port, "t": round(time.monotonic() - START, 4),
                               "method": self.command, "path": self.path, "body": body})
            with LOCK:
                log.write(line + "\n")
                log.flush()

        def do_POST(self):
            self._record()
            self._answer()

        def do_PUT(self):
            self._record()
            self._answer()

        def do_GET(self):
            self._record()
            self._answer(json.dumps({"object_meta": {"name": "detsim-%d" % port},
                                     "status": {"state": "Ready"}}).encode())

        def log_message(self, *args):  # quiet: the log file has every call
            pass

    return Handler


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", required=True, help="file to write one JSON line per call to")
    parser.add_argument("ports", nargs="+", type=int)
    args = parser.parse_args()
    log = open(args.log, "w", encoding="utf-8")
    servers = []
    for port in args.ports:
        server = ThreadingHTTPServer(("127.0.0.1", port), make_handler(port, log))
        server.daemon_threads = True
        threading.Thread(target=server.serve_forever, daemon=True).start()
        servers.append(server)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    print("fake sidecar listening on %d ports" % len(servers), file=sys.stderr, flush=True)
    stop.wait()
    for server in servers:
        server.shutdown()
    log.close()


if __name__ == "__main__":
    main()

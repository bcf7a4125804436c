"""`matcad serve`: the local design page on 127.0.0.1."""

from __future__ import annotations

from matcad.errors import EXIT_OK

HELP = "a local design page: the spec as a form, live prediction, build to a zip"
JSON = False
PORTS = (0, 65535)


def arguments(cmd) -> None:
    cmd.add_argument("--port", type=int, help="port on 127.0.0.1 (default 8765; 0 picks a free one)")


def run(args) -> int:
    from matcad.serve import DEFAULT_PORT, HOST, make_server

    port = DEFAULT_PORT if args.port is None else args.port
    lo, hi = PORTS
    if not lo <= port <= hi:
        raise ValueError(f"--port {port} invalid, must be {lo}-{hi} (0 picks a free port)")
    server = make_server(port)
    print(f"matcad design page on http://{HOST}:{server.server_address[1]}/ (local only; Ctrl-C stops it)",
          flush=True)
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        server.server_close()
    return EXIT_OK

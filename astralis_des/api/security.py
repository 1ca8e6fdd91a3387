"""Safe by default: loopback unless told otherwise; any other address only with CURVE keys.

A key folder (``astralis keys DIR``) holds ZeroMQ certificates: ``server.key`` and
``server.key_secret`` for the server, ``client.key`` and ``client.key_secret`` for a client,
and ``clients/``: the public keys of the clients the server lets in.
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import zmq
import zmq.auth
from zmq.auth.thread import ThreadAuthenticator

from astralis_des.errors import InputError

LOCAL_SCHEMES = ("ipc", "inproc")


def is_local(address: str) -> bool:
    """Does ``address`` reach this machine only? (loopback TCP, IPC or in-process)"""
    scheme, _, rest = address.partition("://")
    if scheme in LOCAL_SCHEMES:
        return True
    host = rest.rsplit(":", 1)[0]
    return scheme == "tcp" and (host.startswith("127.") or host in ("localhost", "[::1]"))


def check_bind(address: str, keys: str | Path | None, key: str = "--bind") -> None:
    if "://" not in address:
        raise InputError(f"'{address}' is not a ZeroMQ address (e.g. tcp://127.0.0.1:5555)",
                         key=key)
    if not is_local(address) and keys is None:
        raise InputError(f"{address} is reachable from other machines; serving there needs "
                         "CURVE keys: --curve-keys DIR (make them with astralis keys DIR)",
                         key=key)


def create_keys(folder: str | Path) -> list[Path]:
    """Write a server and a client certificate pair, and let the client in."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    made = []
    for name in ("server", "client"):
        if (folder / f"{name}.key_secret").exists():
            raise InputError(f"{folder / name}.key_secret exists; not overwriting keys",
                             key="DIR")
    for name in ("server", "client"):
        public, secret = zmq.auth.create_certificates(folder, name)
        made += [Path(public), Path(secret)]
    clients = folder / "clients"
    clients.mkdir(exist_ok=True)
    made.append(Path(shutil.copy(folder / "client.key", clients / "client.key")))
    return made


def _load(path: Path, secret: bool) -> tuple[bytes, bytes | None]:
    if not path.is_file():
        raise InputError(f"{path} is missing (make keys with astralis keys "
                         f"{path.parent})", key="--curve-keys")
    try:
        public, private = zmq.auth.load_certificate(path)
    except (ValueError, OSError) as exc:
        raise InputError(f"{path}: not a ZeroMQ certificate ({exc})", key="--curve-keys") \
            from None
    if secret and private is None:
        raise InputError(f"{path} holds no secret key", key="--curve-keys")
    return public, private


def secure_server(ctx: zmq.Context[Any], sockets: list[zmq.Socket[Any]],
                  folder: str | Path) -> ThreadAuthenticator:
    """Make ``sockets`` CURVE servers that let in only the public keys in ``DIR/clients``."""
    folder = Path(folder)
    public, secret = _load(folder / "server.key_secret", secret=True)
    clients = folder / "clients"
    if not clients.is_dir() or not any(clients.glob("*.key")):
        raise InputError(f"{clients} holds no client public keys (*.key)", key="--curve-keys")
    auth = ThreadAuthenticator(ctx)
    auth.start()
    auth.configure_curve(domain="*", location=str(clients))
    for sock in sockets:
        sock.curve_secretkey = secret
        sock.curve_publickey = public
        sock.curve_server = True
    return auth


def secure_client(sock: zmq.Socket[Any], folder: str | Path) -> None:
    """A client socket with ``DIR/client.key_secret``, trusting ``DIR/server.key``."""
    folder = Path(folder)
    public, secret = _load(folder / "client.key_secret", secret=True)
    server, _ = _load(folder / "server.key", secret=False)
    sock.curve_secretkey = secret
    sock.curve_publickey = public
    sock.curve_serverkey = server

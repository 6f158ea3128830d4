"""Who may talk to the panel, checked before a request reaches the controller.

Independent of the web framework (plain strings in, ``Refused`` out), so the same rules
hold whatever serves the panel:

- Host: only this panel's names (loopback names, the bound address; beyond loopback also
  the machine's host name and addresses). Any other name is DNS rebinding: 421.
- Origin (when a browser sends one): must be the page's own, ``http://<Host>``: 403.
  Comparing with the Host header (already checked) rather than the bound port keeps an
  SSH tunnel (``ssh -L 9000:localhost:8080``) working.
- Token (when the panel has one): every ``/api/`` path needs ``Authorization: Bearer
  <token>`` or ``?token=<token>`` (401); the page and its assets are public.
- POST bodies: ``Content-Type: application/json`` (415; a cross-site form or a no-cors
  fetch cannot send it), a plain ``Content-Length`` of at most ``MAX_BODY`` bytes (400 for
  a malformed one, 413 when larger), no ``Transfer-Encoding`` (411).
"""

from __future__ import annotations

import hmac
import re
import socket
from collections.abc import Mapping
from dataclasses import dataclass
from urllib.parse import urlsplit

MAX_BODY = 64 * 1024  # [bytes]
LOOPBACK = frozenset({"127.0.0.1", "localhost", "::1"})
WILDCARD = frozenset({"0.0.0.0", "::", ""})
#: Never-answering probes: a UDP connect() only picks the route's source address.
PROBES = {socket.AF_INET: "10.255.255.255", socket.AF_INET6: "2001:db8::1"}
_LENGTH = re.compile(r"[0-9]+")


class Refused(Exception):
    """A request the panel will not serve: ``status`` and a one-line reason."""

    def __init__(self, status: int, message: str) -> None:
        super().__init__(message)
        self.status = status


def is_loopback(host: str) -> bool:
    return host in LOOPBACK


def _clip(text: str, n: int = 40) -> str:
    return text if len(text) <= n else text[:n] + "..."


def split_host(value: str) -> tuple[str, int | None]:
    """``'Robot.local:8080'`` → ``('robot.local', 8080)``, ``'[::1]'`` → ``('::1', None)``."""
    if not value or any(c in value for c in "/?#@\\ \t"):
        raise ValueError(value)
    parts = urlsplit("//" + value)
    name = (parts.hostname or "").rstrip(".")
    if not name:
        raise ValueError(value)
    return name, parts.port  # .port raises ValueError for a bad port


def _endpoint(host: str) -> tuple[str, int]:
    """(name, port) of a Host header or an origin's netloc; HTTP's default port 80."""
    name, port = split_host(host.strip().lower())
    return name, port or 80


def lan_address(family: socket.AddressFamily = socket.AF_INET) -> str | None:
    """The address other machines reach this one at (the default route's source), found
    without sending anything; else the host name's first non-loopback address; else None."""
    try:
        with socket.socket(family, socket.SOCK_DGRAM) as s:
            s.connect((PROBES[family], 9))
            addr = str(s.getsockname()[0])
        if not addr.startswith("127.") and addr not in WILDCARD | LOOPBACK:
            return addr
    except OSError:
        pass
    return next(iter(host_addresses(family)), None)


def host_addresses(family: socket.AddressFamily | int = 0) -> list[str]:
    """Non-loopback addresses the host name resolves to (from /etc/hosts or the resolver)."""
    try:
        infos = socket.getaddrinfo(socket.gethostname(), None, family, socket.SOCK_STREAM)
    except OSError:
        return []
    found = [str(i[4][0]).split("%")[0] for i in infos]
    return [a for a in dict.fromkeys(found) if not a.startswith("127.") and a != "::1"]


def machine_names() -> set[str]:
    """This machine's host name (also as ``<name>.local``, mDNS) and its addresses."""
    host = socket.gethostname().lower()
    names = {host, host.split(".")[0] + ".local", *host_addresses()}
    names.update(a for a in (lan_address(socket.AF_INET), lan_address(socket.AF_INET6)) if a)
    return names


@dataclass(frozen=True)
class Guard:
    """The request checks of one panel. ``names``: Host names it answers to (lowercase);
    ``token``: the secret every /api request must carry (None: no token asked)."""

    names: frozenset[str]
    max_body: int = MAX_BODY
    token: str | None = None

    @classmethod
    def for_bind(cls, host: str, *, token: str | None = None,
                 max_body: int = MAX_BODY) -> Guard:
        """Loopback names and ``host``; beyond loopback also the machine's names."""
        names = set(LOOPBACK) | {host.lower().strip("[]")}
        if not is_loopback(host):
            names |= machine_names()
        return cls(frozenset(names - WILDCARD), max_body, token or None)

    def admit(self, method: str, path: str, query: Mapping[str, list[str]],
              headers: Mapping[str, str], local_address: str) -> None:
        """Every check a request passes before any route sees it: Host, Origin, the token
        (for /api paths), the content type (for POST). ``headers``: lowercase names."""
        host = headers.get("host")
        self.check_host(host, local_address)
        self.check_origin(headers.get("origin"), host or "")
        if path.startswith("/api/"):
            self.check_token(query.get("token", [""])[0], headers.get("authorization", ""))
        if method == "POST":
            self.check_content_type(headers.get("content-type"))

    def check_token(self, query_token: str, authorization: str) -> None:
        """Refused 401 unless the Bearer header (else the ``?token=`` query) is the token."""
        if not self.token:
            return
        given = query_token
        scheme, _, credentials = authorization.strip().partition(" ")
        if scheme.lower() == "bearer":       # auth schemes are case-insensitive (RFC 7235)
            given = credentials.strip()
        if not hmac.compare_digest(given.encode(), self.token.encode()):
            raise Refused(401, "missing or wrong token; use Authorization: Bearer <token> "
                               "or ?token=<token>")

    def check_host(self, header: str | None, local_address: str = "") -> str:
        """The request's host name if it is this panel's (or the address the client
        connected to, a literal no rebinding can forge); else Refused 421 (400 if absent)."""
        if not header:
            raise Refused(400, "missing Host header")
        try:
            name, _ = split_host(header.strip().lower())
        except ValueError:
            raise Refused(400, f"malformed Host header {_clip(header)!r}") from None
        local = local_address.lower().removeprefix("::ffff:")
        if name in self.names or (name == local and local not in WILDCARD):
            return name
        raise Refused(421, f"Host {_clip(header)!r} is not a name of this panel (DNS "
                           "rebinding?); open the URL that biped panel printed")

    def check_origin(self, origin: str | None, host_header: str) -> None:
        """Refused 403 unless ``origin`` is absent or exactly ``http://<host_header>``."""
        if origin is None:
            return
        try:
            o = urlsplit(origin.strip().lower())
            same = (o.scheme == "http" and not (o.path or o.query or o.fragment)
                    and _endpoint(o.netloc) == _endpoint(host_header))
        except ValueError:
            same = False
        if not same:
            raise Refused(403, f"cross-origin request from {_clip(origin)!r} refused: the "
                               "panel only answers its own page")

    def check_content_type(self, value: str | None) -> None:
        """Refused 415 unless the media type is application/json (parameters allowed)."""
        media = (value or "").split(";")[0].strip().lower()
        if media != "application/json":
            raise Refused(415, f"Content-Type {_clip(value or 'missing')!r}: POST bodies must "
                               "be application/json")

    def body_length(self, content_length: str | None, transfer_encoding: str | None) -> int:
        """The declared body size [bytes]: 411 for Transfer-Encoding (chunked bodies are not
        read), 400 for a malformed length, 413 above ``max_body``; no header: 0."""
        if transfer_encoding is not None:
            raise Refused(411, f"Transfer-Encoding {_clip(transfer_encoding)!r} is not "
                               f"accepted; send a Content-Length (at most {self.max_body})")
        if content_length is None:
            return 0
        text = content_length.strip()
        if not _LENGTH.fullmatch(text):
            raise Refused(400, f"bad Content-Length {_clip(text)!r}: expected a byte count "
                               f"0-{self.max_body}")
        if len(text) > 12 or int(text) > self.max_body:
            raise Refused(413, f"request body of {_clip(text, 20)} bytes is too large (at "
                               f"most {self.max_body})")
        return int(text)

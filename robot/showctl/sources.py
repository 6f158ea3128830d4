"""Who may send show control: loopback by default; listening beyond it needs an explicit
allow-list of sources, because OSC has no authentication (any datagram that reaches the
port is obeyed). Also ``HOST:PORT`` as the command line writes it."""

from __future__ import annotations

import ipaddress
from dataclasses import dataclass

from robot.errors import ConfigError

Network = ipaddress.IPv4Network | ipaddress.IPv6Network
LOOPBACK_NETS: tuple[Network, ...] = (ipaddress.ip_network("127.0.0.0/8"),
                                      ipaddress.ip_network("::1/128"))


def is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


@dataclass(frozen=True)
class Sources:
    """The networks a datagram may come from (loopback always)."""

    networks: tuple[Network, ...] = LOOPBACK_NETS

    @classmethod
    def parse(cls, text: str | None, *, host: str, flag: str = "--osc-allow") -> Sources:
        """``text``: addresses or networks, comma separated (``192.168.1.20,10.0.0.0/24``).
        Binding ``host`` beyond loopback without one is refused (ConfigError)."""
        if not text:
            if not is_loopback(host):
                raise ConfigError(f"{flag}: listening on {host} (beyond loopback) needs an "
                                  "allow-list of the senders' addresses: OSC has no "
                                  "authentication, anyone who reaches the port is obeyed")
            return cls()
        nets = list(LOOPBACK_NETS)
        for part in (p.strip() for p in text.split(",")):
            try:
                nets.append(ipaddress.ip_network(part, strict=False))
            except ValueError:
                raise ConfigError(f"{flag} {part!r}: expected an IP address or network "
                                  "(192.168.1.20, 192.168.1.0/24, fd00::/8)") from None
        return cls(tuple(nets))

    def allows(self, address: str) -> bool:
        try:
            ip = ipaddress.ip_address(address.split("%")[0])
        except ValueError:
            return False
        if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
            ip = ip.ipv4_mapped
        return any(ip.version == n.version and ip in n for n in self.networks)


def host_port(text: str, *, flag: str) -> tuple[str, int]:
    """``HOST:PORT`` (``[::1]:9001`` for IPv6) as (host, port); ConfigError naming ``flag``."""
    host, sep, port = text.rpartition(":")
    host = host.strip("[]")
    if not sep or not host or not port.isdigit() or not 0 < int(port) <= 65535:
        raise ConfigError(f"{flag} {text!r}: expected HOST:PORT (127.0.0.1:9001)")
    return host, int(port)

"""The optional mDNS/Bonjour announcement of the session (``_apple-midi._udp``),
so a Mac lists it in Audio MIDI Setup's Network window.  Uses python-zeroconf.

Without it a peer connects by address: Audio MIDI Setup > MIDI Network Setup >
Directory "+" with this host's address and the control port (docs/rtp-midi.md).
"""

from __future__ import annotations

import logging
import socket
from typing import Any

from virja.errors import ConfigError
from virja.rtpmidi import SERVICE_TYPE

log = logging.getLogger(__name__)


class Announcement:
    """A registered service; :meth:`close` withdraws it (on the loop that made it)."""

    def __init__(self, zc: Any, info: Any) -> None:
        self._zc = zc
        self.info = info

    async def close(self) -> None:
        try:
            await self._zc.async_unregister_service(self.info)
        finally:
            await self._zc.async_close()


def _addresses(host: str) -> list[bytes]:
    """The addresses to announce: the bound one, or for a wildcard every IPv4
    address of this machine's interfaces (loopback only if there is nothing else)."""
    if host not in ("0.0.0.0", "::", ""):
        try:
            return [socket.inet_pton(socket.AF_INET6 if ":" in host else socket.AF_INET, host)]
        except OSError as exc:
            raise ConfigError(f"--announce: cannot announce address {host!r}: {exc}") from None
    import ifaddr  # a dependency of zeroconf

    found = {str(ip.ip) for adapter in ifaddr.get_adapters() for ip in adapter.ips if ip.is_IPv4}
    outside = sorted(a for a in found if not a.startswith("127."))
    return [socket.inet_aton(a) for a in (outside or sorted(found) or ["127.0.0.1"])]


def service_info(name: str, bound: tuple[str, int]) -> Any:
    from zeroconf import ServiceInfo

    return ServiceInfo(
        SERVICE_TYPE,
        f"{name}.{SERVICE_TYPE}",
        addresses=_addresses(bound[0]),
        port=bound[1],
        server=f"{socket.gethostname().split('.')[0]}.local.",
    )


async def announce(name: str, bound: tuple[str, int]) -> Announcement:
    """Register ``name`` on the control port (on the running event loop, as the
    listener runs); a clear error when mDNS is unavailable."""
    try:
        from zeroconf import Error as ZeroconfError
        from zeroconf.asyncio import AsyncZeroconf
    except ImportError:
        raise ConfigError("--announce needs the zeroconf package (pip install zeroconf)") from None
    if bound[0].startswith("127.") or bound[0] == "::1":
        log.warning(
            "announcing a session bound to %s: only this machine can reach it "
            "(listen on 0.0.0.0 for the network)",
            bound[0],
        )
    info = service_info(name, bound)
    try:
        zc = AsyncZeroconf()
    except OSError as exc:
        raise ConfigError(f"--announce: mDNS is not available here: {exc}") from None
    try:
        await (await zc.async_register_service(info, allow_name_change=True))
    except (OSError, ZeroconfError) as exc:
        await zc.async_close()
        raise ConfigError(
            f"--announce: could not announce {name!r}: {exc or type(exc).__name__}"
        ) from None
    return Announcement(zc, info)

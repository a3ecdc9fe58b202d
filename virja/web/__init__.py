"""The browser viewer: ``--web HOST:PORT`` on serve, replay and jam (docs/web.md)."""

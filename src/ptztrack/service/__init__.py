"""``ptztrack serve``: cameras from a configuration file, run until stopped, their tracks appended to
rotated files, their events out as JSON lines and over MQTT, their health over HTTP, their learned
detector models kept across restarts.

:mod:`~ptztrack.service.config` (the file), :mod:`~ptztrack.service.outputs` (the tracks' files),
:mod:`~ptztrack.service.events` (track and camera events, MQTT), :mod:`~ptztrack.service.health`
(``/healthz``, ``/metrics``) and :mod:`~ptztrack.service.runner` (the cameras' loops).
"""

from ptztrack.service.config import MQTTSection, ServiceCamera, ServiceConfig, load_service_config
from ptztrack.service.runner import serve

__all__ = ["MQTTSection", "ServiceCamera", "ServiceConfig", "load_service_config", "serve"]

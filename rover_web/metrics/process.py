"""What ProcessCollector leaves out: the process's threads (an rclpy executor, Zenoh's and the
server's own: a leak shows here first)."""

from __future__ import annotations

from prometheus_client.core import GaugeMetricFamily


def _threads() -> int | None:
    try:
        with open("/proc/self/status", "rb") as f:
            for line in f:
                if line.startswith(b"Threads:"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


class ThreadsCollector:
    def collect(self):
        threads = _threads()
        if threads is not None:
            yield GaugeMetricFamily("process_threads", "Threads of this process (Python's and native)", threads)

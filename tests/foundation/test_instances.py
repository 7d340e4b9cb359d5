"""AUTODRIVE_INSTANCE in Python (autodrive.core.settings.instance): instance N moves the default
bus port, the web port and the simulator's run dir by the rule of lcm_types/channels.yaml,
leaves an explicit other port alone, and a bad number is an error naming the variable. The
processes side by side: scm.two_instances."""

from __future__ import annotations

import pytest

from autodrive.core import channels
from autodrive.core.settings import InstanceError, instance


def test_instance_zero_keeps_the_defaults(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("AUTODRIVE_INSTANCE", raising=False)
    table = channels.load()
    assert instance().number == 0
    assert instance().lcm_url(table.url_default) == table.url_default
    assert instance().web_port() == table.instances.web_port
    assert instance().sim_run_dir == table.instances.sim_run_dir


def test_instance_moves_ports(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("AUTODRIVE_INSTANCE", "3")
    rule = channels.load().instances
    i = instance()
    assert i.lcm_url("udpm://239.255.76.67:7667?ttl=0") == (
        f"udpm://239.255.76.67:{7667 + 3 * rule.port_step}?ttl=0"
    )
    assert i.lcm_url("udpm://239.255.76.67:7701?ttl=0") == "udpm://239.255.76.67:7701?ttl=0"
    assert i.lcm_url(i.lcm_url("udpm://239.255.76.67:7667")) == i.lcm_url(
        "udpm://239.255.76.67:7667"
    )
    assert i.lcm_url("memq://") == "memq://"
    assert i.web_port() == rule.web_port + 3 * rule.port_step
    assert i.web_port(9000) == 9000  # an explicit --port wins
    assert i.sim_run_dir == f"{rule.sim_run_dir}-3"
    assert "AUTODRIVE_INSTANCE" in i.describe()


@pytest.mark.parametrize("bad", ["x", "-1", "51", "1.5"])
def test_bad_instance_is_named(monkeypatch: pytest.MonkeyPatch, bad: str) -> None:
    monkeypatch.setenv("AUTODRIVE_INSTANCE", bad)
    with pytest.raises(InstanceError, match="AUTODRIVE_INSTANCE"):
        instance()


def test_the_logger_records_the_instance_bus(monkeypatch: pytest.MonkeyPatch) -> None:
    # Debian's lcm-logger knows no AUTODRIVE_INSTANCE: a mission's log must name the moved port
    from autodrive.core import lcmtypes

    monkeypatch.setenv("AUTODRIVE_INSTANCE", "3")
    url = channels.load().url_default
    argv = lcmtypes.logger_argv(url, "-f")
    assert argv == ["lcm-logger", f"--lcm-url={instance().lcm_url(url)}", "-f"]
    assert instance().lcm_url(url) != url

"""What the pythonfmu slaves of the package's Python FMUs share; runs inside the FMU.

The slaves (``railadhesion_creepforce.py``, ``railadhesion_braking.py``,
``railadhesion_monitor.py``, copied into each FMU's ``resources/``) import these functions from
the host's installed ``railadhesion``, in the guarded import that explains a missing package:
:func:`open_slave` starts a slave (the exit work-around of :mod:`railadhesion.export._host`,
the JSON config the builder wrote), :func:`register_variables` registers the variables listed
in that config.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable
from pathlib import Path

from railadhesion.export._host import release_pythonfmu_state_at_exit

__all__ = ["CONFIG_FILE", "open_slave", "register_variables"]

#: The JSON config of a Python FMU in its ``resources/`` (written by the builders, read here).
CONFIG_FILE = "railadhesion_fmu.json"


def open_slave(slave) -> tuple[Path, dict]:
    """Start the pythonfmu slave ``slave``: register the exit hook (a Python host would
    otherwise risk an abort at exit in pythonfmu's binary), read its JSON config and set its
    ``description``, ``version`` and (when the config has one) ``license``.

    Returns
    -------
    (pathlib.Path, dict)
        The slave's ``resources/`` folder and its config.
    """
    release_pythonfmu_state_at_exit(slave.resources)
    resources = Path(slave.resources)
    config = json.loads((resources / CONFIG_FILE).read_text(encoding="utf-8"))
    slave.description = config["description"]
    slave.version = config["fmu_version"]
    if config.get("license"):
        slave.license = config["license"]
    return resources, config


def register_variables(
    slave,
    variables: Iterable[dict],
    *,
    getter: Callable | None = None,
    setter: Callable | None = None,
) -> None:
    """Register the Real variables of the config's ``"variables"`` list with ``slave``.

    Every variable becomes an attribute of the slave: outputs start at 0.0, inputs and
    parameters at their ``start``; parameters are ``fixed``. ``getter(name)`` and
    ``setter(name)``, when given, make the accessor pythonfmu calls for an output and for an
    input or parameter (default: pythonfmu's, the attribute itself).
    """
    from pythonfmu import Fmi2Causality, Fmi2Variability, Real

    for var in variables:
        name = var["name"]
        causality = Fmi2Causality[var["causality"]]
        if causality == Fmi2Causality.output:
            setattr(slave, name, 0.0)
            slave.register_variable(
                Real(name, causality=causality, description=var["description"],
                     getter=None if getter is None else getter(name))
            )  # fmt: skip
            continue
        setattr(slave, name, float(var["start"]))
        variability = Fmi2Variability.fixed if var["causality"] == "parameter" else None
        slave.register_variable(
            Real(name, causality=causality, variability=variability,
                 description=var["description"], setter=None if setter is None else setter(name))
        )  # fmt: skip

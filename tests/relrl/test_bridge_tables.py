"""The bridge's definitions, each stated once: gw_step/14's layout (stepkernel), the foreign
signatures (lib.FOREIGN, which both the ctypes calls and the compiled step are built from),
and the SWI-Prolog version they were taken from."""

from __future__ import annotations

import re

import pytest

from relrl.bridge import lib as L
from relrl.errors import PrologMissing, RelrlError
from tests.conftest import ROOT


def test_gateway_step_head_is_the_kernels_layout() -> None:
    """prolog/gateway.pl's gw_step/14 clause takes its arguments in STEP_ARGUMENTS' order."""
    from relrl.bridge import stepkernel

    text = (ROOT / "prolog" / "gateway.pl").read_text()
    head = re.search(r"^gw_step\(([^)]*)\) :-", text, re.M | re.S)
    assert head, "gw_step/14's clause was not found"
    names = [a.strip().lower() for a in head[1].split(",")]
    assert names == list(stepkernel.STEP_ARGUMENTS)
    assert stepkernel.ARITY == 14 and stepkernel.RESULT == names.index("result")
    assert list(range(*stepkernel.FIELDS)) == list(range(names.index("code"), 14))


def test_the_compiled_steps_signatures_are_the_tables(monkeypatch: pytest.MonkeyPatch) -> None:
    """The digest stepkernel.py keeps is that of FOREIGN's signatures now; a change of
    FOREIGN that stepkernel.py does not follow is refused before anything is compiled."""
    from relrl.bridge import stepkernel

    assert stepkernel.signatures_digest() == stepkernel.SIGNATURES_DIGEST
    monkeypatch.setattr(stepkernel, "FOREIGN",
                        dict(L.FOREIGN, PL_put_nil=("int", "term", "int")))
    assert stepkernel.signatures_digest() != stepkernel.SIGNATURES_DIGEST
    with pytest.raises(RelrlError, match="SIGNATURES_DIGEST"):
        stepkernel.load("no library: refused before it is loaded")


def test_the_ctypes_calls_are_the_tables() -> None:
    from relrl.bridge.calls import prolog

    lib = prolog().lib
    for name, (result, *arguments) in L.FOREIGN.items():
        f = getattr(lib, name[3:])
        assert f.restype is L.CTYPES[result], name
        assert list(f.argtypes) == [L.CTYPES[a] for a in arguments], name


@pytest.mark.parametrize("version", [80504, 100000, 70000])
def test_another_swi_prolog_is_refused_with_one_line(version: int) -> None:
    with pytest.raises(PrologMissing, match=r"^SWI-Prolog \d+\.\d+\.\d+ \(/x/libswipl.so\): "
                                            r"relrl's bridge is built for SWI-Prolog 9"):
        L.check_version(version, "/x/libswipl.so")


def test_the_running_swi_prolog_is_the_one_built_for() -> None:
    from relrl.bridge.calls import prolog

    lib = prolog().lib
    L.check_version(lib.version_info(L.PL_VERSION_SYSTEM), lib.path)
    L.check_version(90004, "libswipl.so")

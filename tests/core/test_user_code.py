"""The user's code at the seam: an exception or a sys.exit inside it becomes one UserCodeError
naming the file and the line (its traceback kept as the cause); Ctrl-C still interrupts."""

import sys

import pytest

from conftest import write_file
from turntable_pin.core.exceptions import InputError, UserCodeError
from turntable_pin.core.interrupts import Interrupted
from turntable_pin.core.user_code import (
    TRACEBACK_ENV,
    call_user,
    import_module_file,
    is_user_code,
    show_traceback,
)


def test_an_exception_inside_the_users_function_names_its_file_line_and_message(tmp_path):
    path = write_file(tmp_path, "def f(x):\n    y = 1\n    return x / 0\n", "m.py")
    module = import_module_file(path, "turntable_pin_test_user_code_m")
    with pytest.raises(UserCodeError) as caught:
        call_user("effect 'x' (class X): f(1)", module.f, 1, path=path)
    error = caught.value
    assert str(error).startswith(f"{path}, line 3: effect 'x' (class X): f(1) raised ")
    assert "ZeroDivisionError: division by zero" in str(error)
    assert TRACEBACK_ENV in str(error) and "\n" not in str(error)
    assert isinstance(error.__cause__, ZeroDivisionError)
    assert not isinstance(error, InputError)  # the fits' `except InputError` must not hide it


def test_a_sys_exit_inside_the_users_function_is_its_error():
    def leaves():
        sys.exit(0)

    with pytest.raises(UserCodeError, match=r"f\(\) called sys.exit\(0\)"):
        call_user("f()", leaves)


@pytest.mark.parametrize("interruption", [KeyboardInterrupt(), Interrupted(15)])
def test_an_interruption_passes_through_the_users_code(interruption):
    def interrupted():
        raise interruption

    with pytest.raises(KeyboardInterrupt):
        call_user("f()", interrupted)


@pytest.mark.parametrize(
    "text, message, line",
    [
        ("import sys\nsys.exit(0)\n", "it called sys.exit(0) while being imported", 2),
        ("import sys\n\nsys.exit('bye')\n", "it called sys.exit('bye')", 3),
        ("x = 1\nraise RuntimeError('no')\n", "cannot import it: RuntimeError: no", 2),
        ("import nothing_here_at_all\n", "cannot import it: ModuleNotFoundError", 1),
        ("def f(:\n", "cannot import it: SyntaxError", 1),
    ],
)
def test_a_module_that_fails_at_import_is_one_line_naming_file_and_line(
    tmp_path, text, message, line
):
    path = write_file(tmp_path, text, "m.py")
    name = "turntable_pin_test_user_code_failing"
    with pytest.raises(UserCodeError) as caught:
        import_module_file(path, name)
    assert str(caught.value).startswith(f"{path}, line {line}: ")
    assert message in str(caught.value) and "\n" not in str(caught.value)
    assert name not in sys.modules


def test_ctrl_c_while_importing_interrupts_and_forgets_the_module(tmp_path):
    path = write_file(tmp_path, "raise KeyboardInterrupt\n", "m.py")
    with pytest.raises(KeyboardInterrupt):
        import_module_file(path, "turntable_pin_test_user_code_ctrl_c")
    assert "turntable_pin_test_user_code_ctrl_c" not in sys.modules


def test_whose_code_it_is_and_when_tracebacks_are_shown(monkeypatch):
    from turntable_pin.measurement.effects.backlash import Backlash

    class Mine:
        pass

    assert is_user_code(Mine) and is_user_code(Mine())
    assert not is_user_code(Backlash) and not is_user_code(InputError("x"))
    for value, shown in (("", False), ("0", False), ("1", True), ("yes", True)):
        monkeypatch.setenv(TRACEBACK_ENV, value)
        assert show_traceback() is shown


def test_importing_a_module_leaves_no_bytecode_beside_it(tmp_path):
    path = write_file(tmp_path, "X = 1\n", "quiet.py")
    before = sys.dont_write_bytecode
    assert import_module_file(path, "turntable_pin_test_user_code_quiet").X == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["quiet.py"]
    assert sys.dont_write_bytecode == before

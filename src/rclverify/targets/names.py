"""The one place an RCL name becomes a name of the generated code (docs/generate.md, "Names").

An RCL identifier is ``[A-Za-z_][A-Za-z0-9_]*'*`` (primes at the end) that is
not one of RCL's reserved words (docs/rcl-language.md); anything else it may
be: ``class``, ``None``, ``delete``, ``x''``.  Each kind of generated name has
its own rule, deterministic, and written so that a reader finds the RCL name
in it:

* :func:`field_name`: a rosidl field name (rosidl_adapter's pattern
  ``^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$``): snake_case words, a prime is the word
  ``prime`` (``x'`` -> ``x_prime``); a word the message generators cannot
  spell (a Python keyword, a C or C++ keyword, a lower-case macro of the C
  library or of GNU C++) takes the suffix ``_field`` (``class`` ->
  ``class_field``; rosidl_generator_py says keywords are unsupported, and its
  C and C++ generators write the name as a struct member).  Also the C++
  struct field of the node's ``Inputs``/``Outputs``, so that the node copies
  ``inputs_.x = msg.x``.
* :func:`py_name`: a Python parameter of ``logic.step``: the name as written,
  ``'`` -> ``_prime``, a keyword (or ``__debug__``) with a trailing ``_``
  (``class`` -> ``class_``, PEP 8's convention).
* :func:`cpp_local`: a quantified variable in C++: ``q`` + one ``p`` per
  prime + ``_`` + the name (``x'`` -> ``qp_x``): injective by construction.
* :func:`package_name`: a ROS package name (REP 144, rosidl's package
  pattern, at least two characters) of a node: its field-style words; one
  letter, a Python or C++ keyword, a
  Python standard module or a ROS package the generated code imports takes
  ``_node`` (``class`` -> ``class_node``: the name is also a Python package, a
  C++ namespace and an executable).
* :func:`msg_name`: a message name (``^[A-Z][A-Za-z0-9]*$``): CamelCase words,
  a prime is ``Prime``; ``None``/``True``/``False`` (Python class names rosidl
  would write) take ``Msg``.
* :func:`constant_name`: a rosidl constant (``^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$``):
  upper-case words; a C macro name (``NULL``, ``EOF``) takes ``_VALUE``.
* ROS node, topic, service and action names are the RCL names themselves (the
  monitors and ``ros diff`` find them by that name); one that breaks ROS 2's
  rules (a prime, a length: :mod:`.rosnames`) is refused (:mod:`.namecheck`).

Two RCL names that give one generated name (``x'`` and ``x_prime``) are
refused by :mod:`.namecheck` with a located error naming both: no rule here
is injective on every pair of names, the check makes the generated tree so.
"""
from __future__ import annotations

import keyword
import re
import sys

#: Python names a parameter cannot have: the hard keywords and ``__debug__`` (assignment is refused)
PY_RESERVED = frozenset(keyword.kwlist) | {"__debug__"}

#: C++20 keywords and alternative tokens (ISO C++ [lex.key], [lex.digraph])
CPP_KEYWORDS = frozenset("""
alignas alignof and and_eq asm auto bitand bitor bool break case catch char char8_t char16_t char32_t class
compl concept const consteval constexpr constinit const_cast continue co_await co_return co_yield decltype
default delete do double dynamic_cast else enum explicit export extern false float for friend goto if inline
int long mutable namespace new noexcept not not_eq nullptr operator or or_eq private protected public register
reinterpret_cast requires return short signed sizeof static static_assert static_cast struct switch template
this thread_local throw true try typedef typeid typename union unsigned using virtual void volatile wchar_t
while xor xor_eq final override import module
""".split())

#: C keywords that are not C++ ones (rosidl_generator_c writes fields as C struct members)
C_KEYWORDS = frozenset("restrict _Bool _Complex _Imaginary _Alignas _Alignof _Atomic _Generic _Noreturn "
                       "_Static_assert _Thread_local".split())

#: lower-case macros a C or C++ translation unit of a ROS 2 build may see (C library, POSIX,
#: GNU C++'s predefined ``linux``/``unix`` under -std=gnu++17, CMake's default for cxx_std_17)
C_MACROS_LOWER = frozenset("errno assert stdin stdout stderr offsetof setjmp va_arg va_start va_end va_copy "
                           "major minor makedev linux unix i386 math_errhandling".split())

#: upper-case macros of the C library and POSIX a rosidl constant must not be named as
C_MACROS_UPPER = frozenset("""NULL EOF BUFSIZ FILENAME_MAX FOPEN_MAX TMP_MAX SEEK_SET SEEK_CUR SEEK_END
EXIT_SUCCESS EXIT_FAILURE RAND_MAX MB_CUR_MAX CHAR_BIT CHAR_MAX CHAR_MIN SCHAR_MAX SCHAR_MIN UCHAR_MAX SHRT_MAX
SHRT_MIN USHRT_MAX INT_MAX INT_MIN UINT_MAX LONG_MAX LONG_MIN ULONG_MAX LLONG_MAX LLONG_MIN ULLONG_MAX SIZE_MAX
DBL_MAX DBL_MIN DBL_EPSILON FLT_MAX FLT_MIN FLT_EPSILON HUGE_VAL HUGE_VALF INFINITY NAN EDOM ERANGE EILSEQ
EINTR EAGAIN ENOMEM EINVAL TRUE FALSE DELETE ERROR IN OUT OPTIONAL CONST VOID DOMAIN OVERFLOW UNDERFLOW
SIGINT SIGTERM SIGKILL SIGABRT SIGSEGV SIGFPE SIGILL BIG_ENDIAN LITTLE_ENDIAN BYTE_ORDER""".split())

#: words no rosidl field (nor the C++ struct field of a node's Inputs/Outputs) may be
FIELD_RESERVED = PY_RESERVED | CPP_KEYWORDS | C_KEYWORDS | C_MACROS_LOWER

#: Interface packages every ROS 2 distribution ships: their types are used, never generated.
STANDARD_PACKAGES = frozenset({
    "std_msgs", "geometry_msgs", "sensor_msgs", "nav_msgs", "builtin_interfaces", "action_msgs", "std_srvs",
    "diagnostic_msgs", "shape_msgs", "stereo_msgs", "trajectory_msgs", "visualization_msgs", "tf2_msgs",
    "example_interfaces", "unique_identifier_msgs", "rcl_interfaces", "lifecycle_msgs", "statistics_msgs"})

#: ROS packages the generated packages import or depend on, besides the standard interface packages
ROS_PACKAGES = frozenset("rclpy rclcpp rclcpp_action launch launch_ros ament_cmake ament_index_python "
                         "rosidl_default_generators rosidl_default_runtime setuptools resource rclverify"
                         .split()) | STANDARD_PACKAGES

#: names a node's package cannot take: it is a Python package, a C++ namespace and an executable
PACKAGE_RESERVED = FIELD_RESERVED | frozenset(sys.stdlib_module_names) | ROS_PACKAGES

#: message names rosidl_generator_py cannot write as a class name
MSG_RESERVED = frozenset({"None", "True", "False"})


def primes(name: str) -> tuple[str, int]:
    """``x''`` -> ``("x", 2)``: the RCL name without its primes, and how many it had."""
    base = name.rstrip("'")
    return base, len(name) - len(base)


def words(name: str) -> list[str]:
    """The lower-case words of RCL name ``name``: camelCase and ``_`` split, each prime a word
    ``prime`` (``wayP'`` -> ``['way', 'p', 'prime']``); ``[]`` for ``_``."""
    base, n = primes(name)
    s = re.sub(r"(?<=[a-z0-9])([A-Z])", r"_\1", base).lower()
    return [w for w in re.split(r"[^a-z0-9]+", s) if w] + ["prime"] * n


def snake(name: str) -> str:
    """The snake_case of ``name``: :func:`words` joined by ``_``, ``f_`` first when empty or
    starting with a digit (``radiationStatus`` -> ``radiation_status``, ``x'`` -> ``x_prime``).
    Matches rosidl's field and package pattern; not checked against keywords (:func:`field_name`)."""
    s = "_".join(words(name))
    return s if s[:1].isalpha() else "f_" + s if s else "f"


def field_name(name: str) -> str:
    """The rosidl field name (and C++ struct field) of RCL variable ``name``: ``x'`` ->
    ``x_prime``, ``class`` -> ``class_field``, ``wayP`` -> ``way_p``."""
    s = snake(name)
    return s + "_field" if s in FIELD_RESERVED else s


def ctor_field(ctor: str, k: int) -> str:
    """The field of argument ``k`` (0-based) of constructor ``ctor``: ``move_0``; never a keyword
    (it ends in a digit)."""
    return f"{snake(ctor)}_{k}"


def py_name(name: str) -> str:
    """The Python parameter of RCL input ``name``: ``x'`` -> ``x_prime``, ``class`` -> ``class_``,
    ``wayP`` stays."""
    base, n = primes(name)
    s = base + "_prime" * n
    return s + "_" if s in PY_RESERVED else s


def cpp_local(name: str) -> str:
    """The C++ name of a quantified variable: ``x`` -> ``q_x``, ``x'`` -> ``qp_x``, ``x''`` ->
    ``qpp_x`` (injective: the prefix is the prime count, the rest the name)."""
    base, n = primes(name)
    return "q" + "p" * n + "_" + base


def package_name(name: str) -> str:
    """The ROS package (Python package, C++ namespace, executable) of node ``name``:
    ``RadiationSensor`` -> ``radiation_sensor``, ``class`` -> ``class_node``, ``A`` -> ``a_node``
    (REP 144: at least two characters)."""
    s = snake(name)
    return s + "_node" if s in PACKAGE_RESERVED or len(s) < 2 else s


def msg_name(name: str) -> str:
    """A message name from RCL name ``name``: ``RadStat`` stays, ``way_p`` -> ``WayP``, ``T'`` ->
    ``TPrime``, ``none`` -> ``NoneMsg``."""
    base, n = primes(name)
    parts = [p for p in re.split(r"[^A-Za-z0-9]+", base) if p] + ["Prime"] * n
    s = "".join(p[:1].upper() + p[1:] for p in parts)
    if not s or not s[0].isalpha():
        s = "T" + s
    return s + "Msg" if s in MSG_RESERVED else s


def constant_name(*parts: str) -> str:
    """A rosidl constant from RCL names: the upper-case words of each part joined by ``_``
    (``constant_name('RadStat', 'red')`` -> ``RAD_STAT_RED``); a C macro name takes ``_VALUE``."""
    s = "_".join(snake(p).upper() for p in parts)
    return s + "_VALUE" if s in C_MACROS_UPPER else s


__all__ = ["CPP_KEYWORDS", "FIELD_RESERVED", "PACKAGE_RESERVED", "PY_RESERVED", "constant_name", "cpp_local",
           "ctor_field", "field_name", "msg_name", "package_name", "primes", "py_name",
           "snake", "words"]

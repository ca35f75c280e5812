"""Just enough of rclcpp, rclcpp_action and rosidl's C++ message headers to compile a generated
``<pkg>_node.cpp`` with ``g++ -fsyntax-only`` where ROS 2's C++ is not installed (ROS 2's PyPI
wheels have no rclcpp).  The message headers are written from the generated ``.msg``/``.srv``/
``.action`` files as rosidl_generator_cpp lays them out (``pkg/msg/snake_name.hpp``, namespace
``pkg::msg``, one member per field, one ``static constexpr`` per constant; a service's
``Request``/``Response``, an action's ``Goal``/``Result``/``Feedback``), so that a field or
constant C++ cannot spell fails to compile here as it would there.  The rclcpp API is declared
with the signatures the generated node calls; nothing runs."""
from __future__ import annotations

import re
from pathlib import Path

_PRIM = {"float64": "double", "float32": "float", "int64": "std::int64_t", "uint64": "std::uint64_t",
         "int32": "std::int32_t", "uint32": "std::uint32_t", "int16": "std::int16_t", "uint16": "std::uint16_t",
         "int8": "std::int8_t", "uint8": "std::uint8_t", "bool": "bool", "byte": "std::uint8_t",
         "char": "char", "string": "std::string"}

#: std_msgs' one-value messages: (name, field type)
STD = {"String": "string", "Bool": "bool", "Float64": "float64", "Float32": "float32", "Int64": "int64",
       "UInt64": "uint64", "Int32": "int32", "UInt32": "uint32", "Int8": "int8", "UInt8": "uint8", "Empty": ""}

RCLCPP = """#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
namespace rclcpp {
struct QoS { explicit QoS(std::size_t) {} };
template <class T> struct Publisher { using SharedPtr = std::shared_ptr<Publisher>; void publish(const T &) {} };
template <class T> struct Subscription { using SharedPtr = std::shared_ptr<Subscription>; };
template <class T> struct Service { using SharedPtr = std::shared_ptr<Service>; };
template <class T> struct Client { using SharedPtr = std::shared_ptr<Client>; };
class Node {
public:
  explicit Node(const std::string &) {}
  virtual ~Node() = default;
  template <class T> typename Publisher<T>::SharedPtr create_publisher(const std::string &, const QoS &)
  { return std::make_shared<Publisher<T>>(); }
  template <class T, class F> typename Subscription<T>::SharedPtr create_subscription(const std::string &,
    const QoS &, F && f) { f(T{}); return std::make_shared<Subscription<T>>(); }
  template <class T, class F> typename Service<T>::SharedPtr create_service(const std::string &, F && f)
  { f(std::make_shared<typename T::Request>(), std::make_shared<typename T::Response>());
    return std::make_shared<Service<T>>(); }
  template <class T> typename Client<T>::SharedPtr create_client(const std::string &)
  { return std::make_shared<Client<T>>(); }
};
inline void init(int, char **) {}
inline void spin(const std::shared_ptr<Node> &) {}
inline void shutdown() {}
}  // namespace rclcpp
"""

RCLCPP_ACTION = """#pragma once
#include <array>
#include <memory>
#include <string>
#include "rclcpp/rclcpp.hpp"
namespace rclcpp_action {
using GoalUUID = std::array<unsigned char, 16>;
enum class GoalResponse { REJECT, ACCEPT_AND_EXECUTE, ACCEPT_AND_DEFER };
enum class CancelResponse { REJECT, ACCEPT };
template <class T> struct ServerGoalHandle {
  std::shared_ptr<const typename T::Goal> get_goal() const { return std::make_shared<typename T::Goal>(); }
  void succeed(std::shared_ptr<typename T::Result>) {}
};
template <class T> struct Server { using SharedPtr = std::shared_ptr<Server>; };
template <class T> struct Client { using SharedPtr = std::shared_ptr<Client>; };
template <class T, class A, class B, class C> typename Server<T>::SharedPtr create_server(rclcpp::Node *,
  const std::string &, A && a, B && b, C && c)
{ auto g = std::make_shared<const typename T::Goal>(); a(GoalUUID{}, g);
  auto h = std::make_shared<ServerGoalHandle<T>>(); b(h); c(h); return std::make_shared<Server<T>>(); }
template <class T> typename Client<T>::SharedPtr create_client(rclcpp::Node *, const std::string &)
{ return std::make_shared<Client<T>>(); }
}  // namespace rclcpp_action
"""


def header_name(name: str) -> str:
    """rosidl's CamelCase to snake_case (rosidl_pycommon): ``WayPEntry`` -> ``way_p_entry``."""
    return re.sub("([a-z0-9])([A-Z])", r"\1_\2", re.sub("(.)([A-Z][a-z]+)", r"\1_\2", name)).lower()


def _struct(name: str, lines: list[str], pkg: str, includes: set[str]) -> str:
    body = []
    for line in lines:
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        typ, rest = line.split(None, 1)
        array = typ.endswith("[]")
        base = typ[:-2] if array else typ
        if base in _PRIM:
            cpp = _PRIM[base]
        else:
            p, n = base.split("/") if "/" in base else (pkg, base)
            includes.add(f"{p}/msg/{header_name(n)}.hpp")
            cpp = f"{p}::msg::{n}"
        cpp = f"std::vector<{cpp}>" if array else cpp
        if "=" in rest:
            const, value = (x.strip() for x in rest.split("=", 1))
            body.append(f"  static constexpr {cpp} {const} = {value};")
        else:
            body.append(f"  {cpp} {rest.strip()}{{}};")
    return f"struct {name}\n{{\n" + "\n".join(body) + "\n};\n"


def _header(pkg: str, kind: str, name: str, text: str) -> str:
    includes: set[str] = set()
    parts = [p.splitlines() for p in re.split(r"^---\s*$", text, flags=re.M)]
    if kind == "msg":
        inner = _struct(name, parts[0], pkg, includes)
    else:
        names = ["Request", "Response"] if kind == "srv" else ["Goal", "Result", "Feedback"]
        inner = f"struct {name}\n{{\n" + "".join(_struct(n, p, pkg, includes) for n, p in zip(names, parts)) + "};\n"
    inc = "".join(f'#include "{i}"\n' for i in sorted(includes))
    return (f"#pragma once\n#include <cstdint>\n#include <string>\n#include <vector>\n{inc}"
            f"namespace {pkg} {{ namespace {kind} {{\n{inner}}} }}\n")


def write_stubs(trees: list[Path], root: Path) -> Path:
    """Write the stub headers for every interface file under ``trees`` (and std_msgs) into
    ``root``; returns ``root`` (the ``-I`` directory)."""
    def put(rel: str, text: str) -> None:
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
    put("rclcpp/rclcpp.hpp", RCLCPP)
    put("rclcpp_action/rclcpp_action.hpp", RCLCPP_ACTION)
    for name, typ in STD.items():
        put(f"std_msgs/msg/{header_name(name)}.hpp", _header("std_msgs", "msg", name, f"{typ} data\n" if typ else ""))
    for t in trees:
        for kind in ("msg", "srv", "action"):
            for f in sorted(t.glob(f"*/{kind}/*.{kind}")):
                put(f"{f.parent.parent.name}/{kind}/{header_name(f.stem)}.hpp",
                    _header(f.parent.parent.name, kind, f.stem, f.read_text()))
    return root

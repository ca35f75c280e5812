# created once by rclverify generate: yours to edit, never overwritten
"""What node HeaterControl does.  The node object (node.py) holds every
end of its contract's interface:
  node.sub_temperature: sub 'temperature' (std_msgs/Float64; in.celsius)
  node.pub_heat: pub 'heat' (std_msgs/Bool; out.heat)

``step`` is the node's decision: the property tests of the plan fragment
(rclverify_plan.yaml) call it with one keyword argument per contract input;
the callbacks below run it on the inputs as they stand (``node.values``)."""

INPUTS = ["celsius"]


def step(celsius):
    """The outputs for these inputs (RCL values, docs/values.md): ``{output name: value}``."""
    return {'heat': celsius < 18}


def setup(node):
    """Called once when the node has made its ends (timers, state)."""


def _run(node):
    """``step`` on the inputs as they stand, once every input has a value; ``{}`` before."""
    if not all(f'in.{n}' in node.values for n in INPUTS):
        return {}
    return step(**{n: node.values[f'in.{n}'] for n in INPUTS})


def on_input(node, var, msg):
    """A message for contract input ``var`` (``'in.x'``) arrived; publish the outputs it decides."""
    for name, value in _run(node).items():
        node.publish_value(f'out.{name}', value)


def on_request(node, service, request, response):
    """A request of service ``service``; fill and return ``response``."""
    for name, value in _run(node).items():
        node.fill(f'out.{name}', response, value)
    return response


def on_goal(node, action, goal_handle):
    """A goal of action ``action``; return its result."""
    goal_handle.abort()
    return None

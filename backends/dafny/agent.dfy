// The Agent node implemented in Dafny, as a refinement of the contract stub
// that rclverify generates from contracts/remote_inspection.rcl (module
// AgentContract, artifacts/dafny/Agent/agent_contract.dfy).  It plays the role
// of the paper's Dafny agent (section "Compositionality enables
// Interchangeability"): a replacement for the Gwendolen agent that is accepted
// as long as it meets the Agent's first-order contract.  Verify it with
// `rclverify` (backend "dafny") or by hand:
//   dafny /compile:0 /arith:2 artifacts/dafny/Agent/agent_contract.dfy backends/dafny/agent.dfy
//
// What it does.  Each step it looks at its inputs (the position predicate
// `at`, the waypoint numbering `wayP`, the inspection record `inspected` and
// the radiation status) and issues one command:
//   1. at a waypoint not yet inspected    -> inspect it            (REQ2, guarantee 2)
//   2. radiation red or orange            -> move to waypoint 0    (REQ3, guarantee 3)
//   3. at an inspected waypoint i          -> move to waypoint i+1  (REQ1, guarantee 1)
//      or, when i is the last waypoint     -> move to waypoint 0
//   4. otherwise                           -> move to waypoint 0
// The inputs are mathematical functions over the reals, so "the position the
// robot is at" is chosen with Dafny's such-that operator (`:|`); that is why
// the contract stub declares a ghost method: this is a verified model of the
// decision procedure, to be re-implemented in the ROS node (as in the paper).
//
// Why it does not verify, and why no implementation can.  The Agent contract
// is transcribed as published.  Its guarantee 3 quantifies the waypoint number
// i universally:
//     forall(x', y' in REAL, i in NATURAL | in.radiationStatus in {red, orange}
//         or not exists(x, y in REAL | in.wayP(x, y) == i + 1) -> <move to waypoint 0>)
// With finitely many waypoints some i (the last one) has no successor, so the
// premise always holds and guarantee 3 demands `move(...)` to waypoint 0 at
// every step, whatever the radiation.  Guarantee 2 demands `inspect(i)`
// whenever the robot is at an uninspected waypoint i.  Both cannot hold at
// once, so the contract has no implementation.  Dafny therefore reports the
// method's postconditions as unproved (each error mapped back to its RCL
// guarantee; the evidence is `inconclusive`: the inputs are functions, so
// rclverify fixes none of them from the prover's model and shows no
// counterexample), and the ghost method
// `PublishedContractIsUnrealisable` below makes the argument checkable: it
// calls the contract on the mission's first step (13 waypoints 0-12 on the
// line y = 0, the robot at waypoint 0, nothing inspected, radiation green)
// and Dafny proves that the contract's guarantees 2 and 3 together imply
// `false` there.
//
// That proof needs Dafny's option /arith:2 (plan entry `options:
// ["/arith:2"]`): guarantee 3 mentions its i only in `i + 1`, so Dafny finds
// no trigger for it ("No terms found to trigger on") and, with the default
// arithmetic encoding, can never instantiate it; /arith:2 makes `+` a function
// symbol the prover can match.  Without the option Dafny also reports the
// proof's last assertion as unproved.
//
// The contract also lacks the assumption that the robot is at exactly one
// position: with `at` true at two uninspected waypoints, guarantee 2 alone
// demands two different commands.
//
// The contract is not weakened here: the stub is regenerated from the RCL
// file and Dafny checks this module against it.
module AgentImpl refines AgentContract {

  ghost method Agent(wayP: WayP, at: AtType, radiationStatus: RadStat, inspected: InspectedType)
    returns (command: CommandSet)
  {
    if x: real, y: real :| at(x, y) && !inspected(wayP(x, y)) {
      command := inspect(wayP(x, y));
    } else if radiationStatus == red || radiationStatus == orange {
      command := Home(wayP);
    } else if x: real, y: real :| at(x, y) {
      var i := wayP(x, y);
      if nx: real, ny: real :| wayP(nx, ny) == i + 1 {
        command := move(nx, ny);
      } else {
        command := Home(wayP);
      }
    } else {
      command := Home(wayP);
    }
  }

  // The command "go to waypoint 0" (the entry point), when there is one.
  ghost method Home(wayP: WayP) returns (command: CommandSet)
    ensures (exists x: real, y: real :: wayP(x, y) == 0) ==>
              exists x: real, y: real :: wayP(x, y) == 0 && command == move(x, y)
  {
    if x: real, y: real :| wayP(x, y) == 0 {
      command := move(x, y);
    } else {
      command := move(0.0, 0.0);
    }
  }

  // The case study's waypoint numbering: waypoint k (1-12) at (k, 0); every
  // other point, the entry point among them, is numbered 0.
  function Waypoint(x: real, y: real): nat
    ensures Waypoint(x, y) <= 12
  {
    if y != 0.0 then 0
    else if x == 1.0 then 1 else if x == 2.0 then 2 else if x == 3.0 then 3
    else if x == 4.0 then 4 else if x == 5.0 then 5 else if x == 6.0 then 6
    else if x == 7.0 then 7 else if x == 8.0 then 8 else if x == 9.0 then 9
    else if x == 10.0 then 10 else if x == 11.0 then 11 else if x == 12.0 then 12
    else 0
  }

  // Any method meeting the Agent contract, called on the first step of the
  // mission, would return a command that is both inspect(0) (guarantee 2) and
  // a move (guarantee 3 with i = 12): Dafny proves this state unreachable.
  ghost method PublishedContractIsUnrealisable()
    ensures false
  {
    var wayP: WayP := (x: real, y: real) => Waypoint(x, y);
    var at: AtType := (x: real, y: real) => x == 0.0 && y == 0.0;
    var inspected: InspectedType := (i: nat) => false;
    var command := Agent(wayP, at, green, inspected);
    // guarantee 2, x' = y' = 0, i = 0: the robot is at uninspected waypoint 0.
    assert at(0.0, 0.0);
    assert wayP(0.0, 0.0) == 0;
    assert !inspected(0);
    assert command == inspect(0);
    // guarantee 3, i = 12: no waypoint 13 exists, so the command must be a move.
    assert !(exists x: real, y: real :: wayP(x, y) == 12 + 1);
    assert exists x'': real, y'': real :: wayP(x'', y'') == 0 && command == move(x'', y'');
  }
}

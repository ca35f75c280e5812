"""The Dafny log shows the verification result, not prover option noise."""
from __future__ import annotations

from rclverify.backends.dafny.runner import filter_log, parse_output

RAW = """\
a.dfy(36,12): Warning: /!\\ No terms found to trigger on.
Prover error: line 18 column 28: unknown parameter 'model_compress'
Legal parameters are:
  auto_config (bool) (default: true)
  timeout (unsigned int) (default: 4294967295)
  warning (bool) (default: true)
b.dfy(59,62): Error BP5003: A postcondition might not hold on this return path.
a.dfy(30,12): Related location: This is the postcondition that might not hold.
Execution trace:
    (0,0): anon0
Prover error: line 4962 column 28: unknown parameter 'model_compress'
Legal parameters are:
  auto_config (bool) (default: true)

Dafny program verifier finished with 0 verified, 1 error
"""


def test_known_prover_option_messages_are_removed_with_a_note():
    text, notes = filter_log(RAW)
    assert "Prover error" not in text and "Legal parameters" not in text and "auto_config" not in text
    # what matters stays: warnings, errors, their traces and the summary
    assert "No terms found to trigger on" in text
    assert "Error BP5003" in text and "    (0,0): anon0" in text
    assert "finished with 0 verified, 1 error" in text
    assert len(notes) == 1 and "removed 2" in notes[0] and "model_compress" in notes[0]


def test_filtering_changes_no_verdict_and_leaves_clean_logs_alone():
    text, _ = filter_log(RAW)
    a, b = parse_output(text), parse_output(RAW)
    assert (a.summary, a.verified, a.errors, a.timeouts) == (b.summary, b.verified, b.errors, b.timeouts) == (True, 0, 1, 0)
    clean = "Dafny program verifier finished with 3 verified, 0 errors\n"
    assert filter_log(clean) == (clean, [])

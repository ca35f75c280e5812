"""The three-band classifier (the case study's Radiation Sensor without its command): the contract
the offline monitor's batch-path tests, its straight-line oracle and the log-reader tests check runs
against."""

#: The node alone (a test with more nodes writes its own context line before it).
CLASSIFIER_NODE = """\
node Classifier {
  inputs( r : REAL )
  outputs( status : Band )
  topics( std_msgs/Float64 reading matches(in.r), std_msgs/String status matches(out.status) )
  assume( 0 <= in.r )
  guarantee( (in.r < 120 -> out.status == green)
         and (120 <= in.r and in.r < 250 -> out.status == orange)
         and (250 <= in.r -> out.status == red) )
}
"""
CLASSIFIER = "context { Band : {green, orange, red} ; }\n" + CLASSIFIER_NODE

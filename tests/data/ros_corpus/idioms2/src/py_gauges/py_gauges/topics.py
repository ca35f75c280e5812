"""Names the gauges share."""
GAUGE_NODE = 'gauge'
READING_TOPIC = 'reading'
ALARM_SERVICE = 'raise_alarm'

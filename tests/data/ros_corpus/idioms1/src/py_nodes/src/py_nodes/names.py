"""Topic names shared by the package's nodes."""
BEACON_TOPIC = 'beacons'
LEVEL_TOPIC = 'battery/level'
RELAY_NODE = 'beacon_relay'

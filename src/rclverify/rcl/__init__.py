"""rcl stage of rclverify."""

"""logic stage of rclverify."""

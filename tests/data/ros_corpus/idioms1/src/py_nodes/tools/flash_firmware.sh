#!/bin/sh
avrdude -p m328p -c arduino -P "$1" -U flash:w:firmware.hex

"""stairbot.drivers: the boards' protocol, serial and CAN transports, URL registry."""

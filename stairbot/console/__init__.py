"""stairbot.console: the Textual operator console."""

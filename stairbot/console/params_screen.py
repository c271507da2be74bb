"""The parameters screen (``i``): the resolved robot config as a tree, each
value with its unit and the config that set it, the limits the controller
works from, and the edit of a runtime-safe value between runs
(console/param_edit.py): typed into a field, checked, shown as a diff with
the new file's whole text, and used only once the operator presses the
"Use it" button (Tab to it, then Enter)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any
from weakref import WeakKeyDictionary

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Static, Tree

from stairbot.console import watching
from stairbot.console.param_edit import RUNTIME_SAFE, Edit, Parameters, allowed, value_of
from stairbot.console.params import Limit, Value, derived_limits, shown_value, values
from stairbot.control.robot_config import load_config
from stairbot.errors import StairbotError
from stairbot.files import shown
from stairbot.inputs.config import RobotConfig
from stairbot.recording.record import RecordsTicks

if TYPE_CHECKING:
    from stairbot.console.app import StairbotConsole

KEY_WIDTH = 32
VALUE_WIDTH = 13
"""Columns for a value and its unit, before the config that set it."""
EDITABLE = "✎"
MID_RUN = ("a run is going on: parameters change between runs only (x stops the run); "
           "nothing changed")


_PARAMETERS: WeakKeyDictionary[StairbotConsole, Parameters] = WeakKeyDictionary()


def parameters(app: StairbotConsole) -> Parameters:
    """The console's changes to the config it started with (made once a console)."""
    found = _PARAMETERS.get(app)
    if found is None:
        found = _PARAMETERS[app] = Parameters(app.engine.world_config)
    return found


def open_parameters(app: StairbotConsole) -> None:
    """``i``: show the parameters screen (once)."""
    if not isinstance(app.screen, ParamsScreen):
        app.push_screen(ParamsScreen(app))


def _label(v: Value, width: int) -> Text:
    """A value's line: its name, value, unit, ✎ when runtime-safe, and (dim)
    the config that set it, in columns."""
    text = Text(f"{v.key.split('.', 1)[1]:<{width}} ")
    value = shown_value(v.value)
    text.append(value, style="bold")
    unit = f" {v.unit}" if v.unit else ""
    text.append(f"{unit:<{VALUE_WIDTH - len(value)}}")
    text.append(f" {EDITABLE} " if v.key in RUNTIME_SAFE else "   ", style="bold green")
    if v.source:
        text.append(v.source, style="dim")
    return text


def _limit_label(limit: Limit) -> Text:
    text = Text(f"{limit.name:<{KEY_WIDTH}} ")
    value = shown_value(limit.value) if not isinstance(limit.value, str) else limit.value
    text.append(value, style="bold")
    if limit.unit:
        text.append(f" {limit.unit}")
    return text


class ParamsScreen(ModalScreen[None]):
    """The resolved config and its derived limits; Enter on a value marked
    ✎ edits it (no run going); Escape closes."""

    DEFAULT_CSS = """
    ParamsScreen { align: center middle; }
    ParamsScreen > Vertical {
        width: 100%; height: 100%; border: thick $primary; background: $surface;
    }
    ParamsScreen #params-title { height: auto; text-style: bold; }
    ParamsScreen Tree { height: 1fr; }
    ParamsScreen #params-say { height: auto; min-height: 1; }
    ParamsScreen #params-say.error { color: $error; }
    ParamsScreen #params-edit-row { height: auto; display: none; }
    ParamsScreen #params-edit-row.editing { display: block; }
    ParamsScreen #params-keys { color: $text-muted; height: 1; }
    """

    BINDINGS = [Binding("escape", "close", "close")]

    def __init__(self, console: StairbotConsole) -> None:
        super().__init__()
        self.console = console
        self.params = parameters(console)
        self.editing: str | None = None
        """The key being edited (its field shown), or None."""
        self.proposed: Edit | None = None
        """The change the diff shows, until it is answered."""

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Static(id="params-title", markup=False)
            yield Tree[Any]("robot config", id="params-tree")
            yield Static(id="params-say", markup=False)
            with Vertical(id="params-edit-row"):
                yield Label(id="params-allowed", markup=False)
                yield Input(id="params-edit", compact=True)
            yield Static("↑↓ · Enter: edit a ✎ value (no run going) · Esc: close · "
                         "space: E-STOP", id="params-keys", markup=False)

    def on_mount(self) -> None:
        self.fill()
        self.query_one(Tree).focus()

    @property
    def config(self) -> RobotConfig:
        """The runs' config, the one shown."""
        return self.console.engine.config

    def fill(self) -> None:
        """The tree, from the runs' config."""
        cfg = self.config
        self.query_one("#params-title", Static).update(
            f"PARAMETERS · the next run uses {self.params.describe_source()}")
        tree = self.query_one(Tree)
        tree.clear()
        tree.root.expand()
        rows, note = values(cfg)
        sections: dict[str, Any] = {}
        for v in rows:
            section = v.key.split(".", 1)[0]
            if section not in sections:
                sections[section] = tree.root.add(Text(f"[{section}]"), expand=True)
            sections[section].add_leaf(_label(v, KEY_WIDTH - 4), data=v)
        derived = tree.root.add(Text("derived: what the controller works from"),
                                expand=True)
        groups: dict[str, Any] = {}
        for limit in derived_limits(cfg):
            if limit.group not in groups:
                groups[limit.group] = derived.add(Text(limit.group), expand=True)
            groups[limit.group].add_leaf(_limit_label(limit), data=limit)
        self.tell(note or "✎: runtime-safe, changed between runs (Enter); dim: the "
                  "config that set the value", error=False)

    def show_key(self, key: str) -> None:
        """Move the tree's cursor to the value ``key``."""
        tree = self.query_one(Tree)
        for line in range(tree.last_line + 1):
            node = tree.get_node_at_line(line)
            if node is not None and isinstance(node.data, Value) and node.data.key == key:
                tree.cursor_line = line
                tree.scroll_to_node(node, animate=False)
                return

    def tell(self, message: str, *, error: bool) -> None:
        say = self.query_one("#params-say", Static)
        say.update(message)
        say.set_class(error, "error")

    # -- choosing and editing --------------------------------------------------------
    def on_tree_node_highlighted(self, event: Tree.NodeHighlighted[Any]) -> None:
        data = event.node.data
        if isinstance(data, Value):
            if data.key in RUNTIME_SAFE:
                self.tell(f"{data.key}: runtime-safe; allowed: "
                          f"{allowed(data.key, self.params.started)}", error=False)
            else:
                self.tell(f"{data.key}: not runtime-safe (what the robot is or sees): "
                          "it changes in the config file", error=False)
        elif isinstance(data, Limit):
            self.tell(f"{data.name}: worked out by {data.by}", error=False)

    def on_tree_node_selected(self, event: Tree.NodeSelected[Any]) -> None:
        data = event.node.data
        if isinstance(data, Value):
            event.stop()
            self.edit(data.key)

    def edit(self, key: str) -> None:
        """Open the field for ``key``, or say why not."""
        if key not in RUNTIME_SAFE:
            self.refuse(f"{key} is not runtime-safe: it changes in the config file, for "
                        "a console started on it; runtime-safe: values marked ✎")
            return
        if self.console.engine.running:
            self.refuse(MID_RUN)
            return
        if watching.is_watching(self.console):
            self.refuse("watching: another console controls this robot and its runs; "
                        "nothing changed")
            return
        self.editing = key
        self.tell(f"{key}: now {shown_value(value_of(self.config, key))}; allowed: "
                  f"{allowed(key, self.params.started)}", error=False)
        self.query_one("#params-allowed", Label).update(
            f"{key} = ?   Enter checks it · Esc: no change")
        field = self.query_one("#params-edit", Input)
        field.value = shown_value(value_of(self.config, key))
        self.query_one("#params-edit-row").add_class("editing")
        field.focus()

    def refuse(self, message: str) -> None:
        self.tell(message, error=True)
        self.console.say(message, "warning")

    def close_field(self) -> None:
        self.editing = None
        self.query_one("#params-edit-row").remove_class("editing")
        self.query_one(Tree).focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        key = self.editing
        if key is None:
            return
        if self.console.engine.running:
            self.refuse(MID_RUN)
            return
        try:
            change = self.params.propose(self.config, key, event.value)
        except StairbotError as exc:
            self.tell(f"not changed: {exc}", error=True)
            return
        self.proposed = change
        self.app.push_screen(DiffScreen(change, self.config), self.decided)

    def decided(self, use: bool | None) -> None:
        """The diff answered: write the file and use it (only on "Use it")."""
        change, self.proposed = self.proposed, None
        if not use or change is None:
            self.close_field()
            self.tell("nothing changed: the old value kept", error=False)
            return
        if self.console.engine.running:
            self.refuse(MID_RUN)
            return
        taken = (self.params.overrides, self.params.written)
        try:
            path = self.params.write(change)
            cfg = load_config(path)
            self.params.check_rest(cfg, change.overrides)
        except (StairbotError, OSError) as exc:
            self.params.overrides, self.params.written = taken  # the runs keep their config
            self.refuse(f"not changed: cannot write or read the new config: {exc}")
            return
        self.console.engine.config = cfg
        self.close_field()
        self.fill()
        self.show_key(change.key)
        message = (f"parameters: {change.key} {shown_value(change.old)} → "
                   f"{shown_value(change.new)}; the next run uses {shown(path)}")
        if isinstance(self.console.engine.recorder, RecordsTicks):
            message += ("; the MCAP record holds the config it started with (w twice "
                        "starts one with this)")
        self.tell(message, error=False)
        self.console.say(message, "information")
        if not self.console.engine.latched:  # the latch's line stays the one to know
            self.console.state.set_status(message=message, severity="info")

    def action_close(self) -> None:
        if self.editing is not None:
            self.close_field()
            self.tell("nothing changed", error=False)
            return
        self.dismiss(None)


class DiffScreen(ModalScreen[bool]):
    """The change before it is used: old → new, the derived figures that
    change with it, and the new file's whole text.  "Use it" (Tab, Enter)
    writes and uses it; Escape or "Keep the old" changes nothing.  The focus
    starts on "Keep the old": an Enter pressed once too often keeps it."""

    DEFAULT_CSS = """
    DiffScreen { align: center middle; }
    DiffScreen > Vertical {
        width: 78; max-width: 100%; height: auto; max-height: 100%;
        border: thick $warning; background: $surface; padding: 0 1;
    }
    DiffScreen VerticalScroll {
        height: auto; max-height: 12; border: round $primary; background: $panel;
    }
    DiffScreen .buttons { height: 1; align: center middle; }
    DiffScreen Button { margin: 0 2; }
    """

    BINDINGS = [Binding("escape", "keep", "keep the old")]

    def __init__(self, change: Edit, before: RobotConfig) -> None:
        super().__init__()
        self.change, self.before = change, before

    def compose(self) -> ComposeResult:
        c = self.change
        with Vertical():
            yield Static(self.summary(), markup=False)
            with VerticalScroll():
                yield Static(c.text.rstrip("\n"), markup=False, id="diff-text")
            with Horizontal(classes="buttons"):
                yield Button("Keep the old (Esc)", id="keep", compact=True)
                yield Button("Use it", id="use", variant="warning", compact=True)

    def summary(self) -> str:
        c = self.change
        lines = [f"For the next run: {c.key}  {shown_value(c.old)} → {shown_value(c.new)}"]
        before = {(limit.group, limit.name): limit for limit in
                  derived_limits(self.before)}
        moved = [f"  {limit.name}  {shown_value(before[(limit.group, limit.name)].value)} → "
                 f"{shown_value(limit.value)} {limit.unit or ''}".rstrip()
                 for limit in derived_limits(c.config)
                 if (limit.group, limit.name) in before
                 and before[(limit.group, limit.name)].value != limit.value]
        if moved:
            lines.append("derived figures that change with it:")
            lines += moved
        lines.append(f"It writes a new file (never over one): {shown(c.path)}, whole:")
        return "\n".join(lines)

    def on_mount(self) -> None:
        self.query_one("#keep", Button).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(event.button.id == "use")

    def action_keep(self) -> None:
        self.dismiss(False)


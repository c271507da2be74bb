"""The signal picker (key ``v``): every signal the console knows, listed
with its unit (console/signals.py); the operator picks up to
:data:`~stairbot.console.signals.MAX_PICKED` in at most
:data:`~stairbot.console.signals.MAX_UNITS` units, and ``v`` (or the Plot
button) plots them in the graphs' place.  Picking none gives the graphs
back.  Enter (or a click) picks or drops the highlighted signal: space is
the emergency stop on every screen, so it cannot toggle here.  Escape
leaves the plot as it was."""

from __future__ import annotations

from collections.abc import Sequence

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Horizontal, Vertical
from textual.screen import ModalScreen
from textual.widgets import Button, Label, SelectionList
from textual.widgets.selection_list import Selection

from stairbot.console.signals import MAX_PICKED, MAX_UNITS, Signal, by_key, fits

HINT = (f"Enter: pick / drop (up to {MAX_PICKED}, in at most {MAX_UNITS} units) · "
        "v: plot them · Esc: as it was")


class PlotPicker(ModalScreen[tuple[str, ...] | None]):
    """Dismisses with the keys of the signals picked, in the order picked
    (empty: the graphs back), or None (Escape: nothing changes)."""

    BINDINGS = [Binding("v", "plot", "plot"), Binding("escape", "cancel", "as it was")]
    DEFAULT_CSS = """
    PlotPicker { align: center middle; }
    PlotPicker .dialog { height: 90%; max-height: 30; }
    PlotPicker SelectionList { height: 1fr; }
    PlotPicker .dialog Label { width: 100%; }
    PlotPicker #picker-why { color: $error; height: auto; }
    """

    def __init__(self, signals: Sequence[Signal], picked: Sequence[str]) -> None:
        super().__init__()
        self.signals = by_key(signals)
        self.order = [k for k in picked if k in self.signals]
        """The keys picked, in the order picked (their lines' colours)."""
        self.list: SelectionList[str] = SelectionList(
            *(Selection(self._prompt(s), s.key, s.key in self.order) for s in signals),
            id="picker-list")
        self.why = Label("", id="picker-why", markup=False)

    @staticmethod
    def _prompt(s: Signal) -> Text:
        out = Text(f"{s.group:<17}", "dim")
        out.append(f"{s.label} ")
        out.append(f"({s.unit})", "bold")
        return out

    def compose(self) -> ComposeResult:
        with Vertical(classes="dialog wide"):
            yield Label("Plot signals over time", classes="question")
            yield self.list
            yield self.why
            yield Label(HINT, classes="hint", markup=False)
            with Horizontal(classes="buttons"):
                yield Button("Plot (v)", variant="primary", id="plot", compact=True)
                yield Button("None: the graphs", id="none", compact=True)
                yield Button("Cancel (Esc)", id="cancel", compact=True)

    def on_mount(self) -> None:
        self.list.focus()

    def on_selection_list_selected_changed(
            self, event: SelectionList.SelectedChanged[str]) -> None:
        """Keep the order picked; refuse a pick past the limits, saying why."""
        event.stop()
        now = self.list.selected
        order = [k for k in self.order if k in now] + [k for k in now if k not in self.order]
        if order == self.order:  # the refused pick dropped again: the reason stays
            return
        self.order = order
        why = fits([self.signals[k] for k in self.order])
        if why:
            dropped = self.order.pop()
            self.list.deselect(dropped)
            self.why.update(f"{self.signals[dropped].name} not picked: {why}; "
                            "drop one first (Enter on it)")
        else:
            self.why.update("")

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        if event.button.id == "plot":
            self.action_plot()
        elif event.button.id == "none":
            self.dismiss(())
        else:
            self.action_cancel()

    def action_plot(self) -> None:
        self.dismiss(tuple(self.order))

    def action_cancel(self) -> None:
        self.dismiss(None)

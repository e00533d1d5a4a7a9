// The one rule for how a click changes the selection, in every view and list: a plain click
// selects one placement alone; Shift, Ctrl or Cmd adds it to the selection (or takes it out).

/// True when pointer or mouse event `e` adds to the selection instead of replacing it.
export const addsToSelection = (e) => !!(e && (e.shiftKey || e.ctrlKey || e.metaKey));

"""Independent checks of the engine: the validation studies and their table, a slow reference
engine to compare event by event, and the overlap audit."""

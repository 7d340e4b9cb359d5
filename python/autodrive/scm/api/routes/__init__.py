"""One APIRouter per resource: session (login), state (status, map, state, signs), vehicles
(poses and their history), lights (states, programs, junction modes), events, live (/ws)."""

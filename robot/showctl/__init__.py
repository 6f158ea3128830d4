"""Show control: OSC and MIDI in (one address space of typed actions, coalesced to the
loop's rate, the e-stop on a path of its own) and status out over OSC."""

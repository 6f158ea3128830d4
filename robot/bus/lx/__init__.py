"""HiWonder/LewanSoul LX serial bus servos on pyserial: the bus (``bus``), its wire
(``port``), packets (``packet``), the command set as data (``tables``), the status read
in turn (``status``) and what the wire carries per tick (``wire``)."""

"""The live puppeteering panel: a controller around the Streamer, an HTTP/JSON server and
the stick-figure geometry the page draws (`biped panel`)."""

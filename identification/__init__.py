"""Material identification: tensile test curves of colon tissue -> Mooney-Rivlin parameters."""

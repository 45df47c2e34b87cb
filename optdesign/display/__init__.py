"""Display primitives: a value, a table, a requirement's row and a figure in the user's
units and words. They import nothing above the shared utilities, so that every layer -
a study wording a refusal, a formulation naming its rows, a report - may use them."""

#!/usr/bin/perl
# Api.OpenApiLint: api/openapi.yaml is a valid OpenAPI 3.0 document.
#   openapi_lint.pl [FILE]        (default: api/openapi.yaml beside this test)
# Exits 0 when clean, 1 listing every problem otherwise.
#
# JSON::Validator (package libjson-validator-perl) checks the document against
# the OpenAPI 3.0 schema (packaged as openapi-specification): unknown keys
# (a description cut by an unquoted ", " becomes one), wrong types, every
# $ref resolved.  That schema cannot express a few rules of the specification
# text, checked here by walking the document:
#   - `nullable` widens only a `type` in the same schema object (3.0.3);
#   - each {name} of a path template has one `in: path` parameter, and each
#     `in: path` parameter a {name};
#   - operationIds are unique;
#   - every media-type `example` is valid against its schema.
use strict;
use warnings;
use File::Basename qw(dirname);
use File::Spec;
use Cwd qw(abs_path);

my $file = $ARGV[0] // File::Spec->catfile(dirname(__FILE__), '..', '..', 'api', 'openapi.yaml');
-r $file or die "openapi_lint: cannot read $file\n";
$file = abs_path($file);
eval { require JSON::Validator::Schema::OpenAPIv3; 1 }
  or die "openapi_lint: JSON::Validator is missing (package libjson-validator-perl; scripts/install-deps.sh)\n";

my @problems;
my $openapi = eval { JSON::Validator::Schema::OpenAPIv3->new($file) };
if (!$openapi) {    # unreadable YAML or an unresolved $ref
  (my $why = $@) =~ s/ at \S+ line \d+\.?\n?\z//;
  print "openapi_lint: $file: $why\n";
  exit 1;
}
push @problems, map {"$_"} @{$openapi->errors};

my $doc = $openapi->data;

# Every object below `node`, with its JSON pointer; a $ref is not followed,
# so each object is seen once, where it is written.
sub walk {
  my ($node, $pointer, $visit) = @_;
  if (ref $node eq 'HASH') {
    $visit->($node, $pointer);
    walk($node->{$_}, "$pointer/" . escape($_), $visit) for sort keys %$node;
  } elsif (ref $node eq 'ARRAY') {
    walk($node->[$_], "$pointer/$_", $visit) for 0 .. $#$node;
  }
}
sub escape { my $k = shift; $k =~ s/~/~0/g; $k =~ s{/}{~1}g; $k }

# The object a local $ref names (JSON::Validator has checked that it exists).
sub deref {
  my $node = shift;
  while (ref $node eq 'HASH' && defined(my $ref = $node->{'$ref'})) {
    $node = $openapi->get($ref =~ s/^#//r);
  }
  return $node;
}

# `nullable` beside `type`.  Examples hold data, not schemas: skipped.
walk($doc, '', sub {
  my ($node, $pointer) = @_;
  return if $pointer =~ m{/examples?(/|$)};
  push @problems, "$pointer: `nullable` without `type` in the same schema (OpenAPI 3.0.3 ignores it there)"
    if exists $node->{nullable} && !exists $node->{type};
});

# Path parameters.
my %operation_ids;
my @methods = qw(get put post delete options head patch trace);
for my $path (sort keys %{$doc->{paths} // {}}) {
  my $item = $doc->{paths}{$path};
  my %in_template = map { $_ => 1 } $path =~ /\{([^}]+)\}/g;
  for my $method (grep { $item->{$_} } @methods) {
    my $op = $item->{$method};
    my $where = "/paths/" . escape($path) . "/$method";
    my %declared;
    for my $p (map { deref($_) } @{$item->{parameters} // []}, @{$op->{parameters} // []}) {
      $declared{$p->{name}} = 1 if ($p->{in} // '') eq 'path';
    }
    push @problems, "$where: path parameter {$_} is not declared `in: path`"
      for grep { !$declared{$_} } sort keys %in_template;
    push @problems, "$where: parameter $_ is `in: path` but not in the path"
      for grep { !$in_template{$_} } sort keys %declared;
    if (defined(my $id = $op->{operationId})) {
      push @problems, "$where: operationId $id is also $operation_ids{$id}" if $operation_ids{$id};
      $operation_ids{$id} //= $where;
    }
  }
}

# Examples against their schemas.
walk($doc, '', sub {
  my ($node, $pointer) = @_;
  return unless $pointer =~ m{/content/[^/]+$} && exists $node->{example} && $node->{schema};
  push @problems, map {"$pointer/example: $_"} $openapi->validate($node->{example}, $node->{schema});
});

if (@problems) {
  print "openapi_lint: $file: $_\n" for @problems;
  print "openapi_lint: ", scalar(@problems), " problem(s)\n";
  exit 1;
}
printf "openapi_lint: %s is valid (%d paths)\n", $file, scalar keys %{$doc->{paths}};
